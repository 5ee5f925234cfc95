//! The actuator drivers: the gimbal (FashionStar servos), the galvo (DAC
//! loop) and the stepper (STEP/DIR) behind one interface, and the target
//! selection ([`Drivers`]: the driver(s) that draw, `target both`
//! included).
//!
//! The drivers do not extend the core: each answers the interface's
//! questions here (whether it reaches a board point, what it waits for,
//! what laser it carries, how fast it may mark: one `match` each), and
//! does its work in its own files, given what it needs ([`stage::Stage`]:
//! the session's motion queue, the run, the settings and geometry, the
//! request numbers). Its G-code stage is a method of its own state
//! ([`DriverJobs`]: the galvo's stroke, the gimbal's stream, the
//! stepper's job); its point runs and what its reports ask of the core
//! ([`Said`]) are functions of its module. The core and the session call
//! them and do what only they do after (stop, alarm, answer a line).
//! Enum dispatch: a [`Driver`] is one byte, nothing allocated. A new
//! actuator is a new variant here, its answers in these `match`es, its
//! files, and its link in the shell (ARCHITECTURE.md, "Adding a driver").

use crate::domain::units::mm_from_cm;
use crate::domain::{Actuator, Aimer, PointCm};
use crate::grbl::PointMm;
use crate::settings::Settings;
use crate::stepper::HomingFailure;
use crate::text::ReplyText;

/// The reply to galvo commands when no galvo loop serves the link.
pub(in crate::sequencer) const NO_GALVO: &str = "this build has no galvo output";
/// The reply to `target stepper` when no stepper task serves the link.
pub(in crate::sequencer) const NO_STEPPER: &str = "this build has no stepper output";

/// One actuator driver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::sequencer) enum Driver {
    /// The servo gimbal.
    Gimbal,
    /// The stepper pan/tilt.
    Stepper,
    /// The two-mirror galvo scanner.
    Galvo,
}

/// How a pattern's path runs on the drivers that draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::sequencer) enum PathRun {
    /// Point by point along the path's cursor (the gimbal; the stepper
    /// with `model seed`).
    Points,
    /// Traced exactly by the driver's own planner (the stepper).
    Traced,
    /// Marked whole by the driver's loop (the galvo alone).
    Marked,
    /// Not drawn (the gimbal and the galvo together draw no paths).
    Refused,
}

/// What a point of a pattern waits for on a driver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::sequencer) enum Arrival {
    /// The move's arrival (servo outcome or stepper at rest).
    Move,
    /// The job's end (galvo `done`).
    Job,
}

impl Driver {
    /// Whether it moves the gimbal's servos (a dead servo refuses and
    /// stops it, and darkens its laser).
    pub(in crate::sequencer) const fn needs_servos(self) -> bool {
        matches!(self, Driver::Gimbal)
    }

    /// Whether it carries the gimbal laser output, which the sequencer
    /// switches (the galvo's laser is switched per sample by its loop).
    pub(in crate::sequencer) const fn carries_laser_pin(self) -> bool {
        matches!(self, Driver::Gimbal | Driver::Stepper)
    }

    /// Whether a G-code line is split into path steps (`path.step_cm`)
    /// for it (the others take a line whole).
    pub(in crate::sequencer) const fn steps_lines(self) -> bool {
        matches!(self, Driver::Gimbal)
    }

    /// Whether it takes a G-code arc whole, as one move along the arc
    /// (the others are sent its chords within `$12`, one step each).
    pub(in crate::sequencer) const fn takes_arcs_whole(self) -> bool {
        matches!(self, Driver::Stepper)
    }

    /// Whether `$H` homes it with switches (the others go to the origin).
    pub(in crate::sequencer) const fn homes_with_switches(self) -> bool {
        matches!(self, Driver::Stepper)
    }

    /// Whether its M4 power follows a speed it does not report by events
    /// (re-applied every stream period while it moves lit).
    pub(in crate::sequencer) const fn polls_speed(self) -> bool {
        matches!(self, Driver::Stepper)
    }

    /// Whether its laser power is on/off at the programmed S (reported
    /// as such), rather than the level the laser output runs at.
    pub(in crate::sequencer) const fn reports_programmed_power(self) -> bool {
        matches!(self, Driver::Galvo)
    }

    /// What a pattern's point waits for on it.
    pub(in crate::sequencer) const fn arrival(self) -> Arrival {
        match self {
            Driver::Gimbal | Driver::Stepper => Arrival::Move,
            Driver::Galvo => Arrival::Job,
        }
    }

    /// Whether it reaches board point `p` (cm) with the geometry
    /// `aimer` of `settings`.
    pub(in crate::sequencer) fn reaches(
        self,
        aimer: &Aimer,
        settings: &Settings,
        p: PointCm,
    ) -> bool {
        match self {
            Driver::Gimbal => aimer.aim(p).is_ok(),
            Driver::Galvo => aimer.galvo_in_range(p),
            Driver::Stepper => stepper::reaches(settings, p),
        }
    }

    /// Every driver, in the order of [`Driver::slot`].
    pub(in crate::sequencer) const ALL: [Driver; 3] =
        [Driver::Gimbal, Driver::Stepper, Driver::Galvo];

    /// Its slot in a per-driver table (the soft-limit check's proven
    /// rectangles).
    pub(in crate::sequencer) const fn slot(self) -> usize {
        match self {
            Driver::Gimbal => 0,
            Driver::Stepper => 1,
            Driver::Galvo => 2,
        }
    }

    /// The board point (mm) where its reach limits may turn along a
    /// rectangle's edges (the soft-limit check's proof,
    /// `sequencer/gcode/reach.rs`), or `None` when the geometry is not one
    /// the proof covers (board roll, an error model, a board nearer than
    /// OL).
    pub(in crate::sequencer) fn monotone_axis(
        self,
        settings: &Settings,
        aimer: &Aimer,
    ) -> Option<PointMm> {
        let frame = match self {
            Driver::Galvo => return Some(PointMm::ZERO),
            Driver::Gimbal => {
                let g = &aimer.gimbal().geometry;
                let zero_model = *aimer.error_model() == kinematics_core::ErrorModel::default();
                (zero_model && g.frame.oq_cm + g.frame.pose.dx_cm > g.ol_cm).then_some(g.frame)?
            }
            Driver::Stepper => stepper::config(settings).gimbal.geometry.frame,
        };
        (frame.pose.roll_deg == 0.0).then_some(PointMm {
            x_mm: mm_from_cm(frame.pose.dy_cm - frame.x_offset_cm),
            y_mm: mm_from_cm(-frame.pose.dz_cm - frame.y_offset_cm),
        })
    }

    /// Its highest marking feed, mm/min (unlimited: infinity).
    pub(in crate::sequencer) fn feed_cap_mm_min(self, settings: &Settings) -> f64 {
        match self {
            Driver::Galvo => settings.galvo.mark_speed_mm_s * 60.0,
            Driver::Gimbal | Driver::Stepper => f64::INFINITY,
        }
    }
}

/// The driver(s) that draw: the target selection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::sequencer) struct Drivers(Actuator);

impl Drivers {
    /// The driver(s) of `target <actuator>`.
    pub(in crate::sequencer) const fn of(actuator: Actuator) -> Self {
        Drivers(actuator)
    }

    /// The drivers that draw, in the order a point is sent to them.
    pub(in crate::sequencer) fn iter(self) -> impl Iterator<Item = Driver> {
        let drivers: &'static [Driver] = match self.0 {
            Actuator::Gimbal => &[Driver::Gimbal],
            Actuator::Galvo => &[Driver::Galvo],
            Actuator::Both => &[Driver::Gimbal, Driver::Galvo],
            Actuator::Stepper => &[Driver::Stepper],
        };
        drivers.iter().copied()
    }

    /// Whether any driver that draws answers `question` with yes.
    pub(in crate::sequencer) fn any(self, question: impl Fn(Driver) -> bool) -> bool {
        self.iter().any(question)
    }

    /// Whether several drivers draw together, step by step (`target
    /// both`): no driver runs ahead with its own planning.
    pub(in crate::sequencer) fn lockstep(self) -> bool {
        self.iter().count() > 1
    }

    /// Whether the gimbal alone draws G-code: it streams the blocks
    /// through its look-ahead plan.
    pub(in crate::sequencer) fn gimbal_streams(self) -> bool {
        self.0 == Actuator::Gimbal
    }

    /// Whether the stepper draws G-code: blocks are handed over to its
    /// task whole.
    pub(in crate::sequencer) fn hands_over_blocks(self) -> bool {
        self.0 == Actuator::Stepper
    }

    /// Whether every driver that draws reaches board point `p` (cm).
    pub(in crate::sequencer) fn reach(
        self,
        aimer: &Aimer,
        settings: &Settings,
        p: PointCm,
    ) -> bool {
        self.iter().all(|d| d.reaches(aimer, settings, p))
    }

    /// The lowest marking feed cap of the drivers that draw, mm/min.
    pub(in crate::sequencer) fn feed_cap_mm_min(self, settings: &Settings) -> f64 {
        self.iter()
            .map(|d| d.feed_cap_mm_min(settings))
            .fold(f64::INFINITY, f64::min)
    }

    /// How a pattern's path runs; `exact`: the exact aiming model.
    pub(in crate::sequencer) fn path_run(self, exact: bool) -> PathRun {
        match self.0 {
            Actuator::Stepper if exact => PathRun::Traced,
            Actuator::Gimbal | Actuator::Stepper => PathRun::Points,
            Actuator::Galvo => PathRun::Marked,
            Actuator::Both => PathRun::Refused,
        }
    }

    /// Whether `target <actuator>` can be served: `Err` with the reason
    /// when its link is not (the gimbal's always is).
    pub(in crate::sequencer) fn check_attached(
        actuator: Actuator,
        galvo_attached: bool,
        stepper_attached: bool,
    ) -> Result<(), &'static str> {
        match actuator {
            Actuator::Gimbal => Ok(()),
            Actuator::Stepper if stepper_attached => Ok(()),
            Actuator::Stepper => Err(NO_STEPPER),
            Actuator::Galvo | Actuator::Both if galvo_attached => Ok(()),
            Actuator::Galvo | Actuator::Both => Err(NO_GALVO),
        }
    }
}

/// What a driver's report (beyond what the G-code session takes of it)
/// asks of the core.
#[derive(Debug, Clone)]
pub(in crate::sequencer) enum Said {
    /// Nothing.
    Nothing,
    /// The run's move `seq` arrived: its dwell starts.
    Arrived(u32),
    /// A job `seq` is done (the run's, if it is its job in flight).
    JobDone(u32),
    /// A notice line, then everything stops for the reason given.
    Stop(Option<ReplyText>, &'static str),
    /// A notice line.
    Notice(ReplyText),
    /// Homing ended at `steps` (`Some`: why it failed), told in a notice.
    Homed(ReplyText, [i32; 2], Option<HomingFailure>),
}

/// What each driver keeps of the G-code job: its own state, which only
/// its files change.
#[derive(Debug, Clone)]
pub(in crate::sequencer) struct DriverJobs {
    /// The gimbal's look-ahead plan and the block it follows.
    pub(in crate::sequencer) gimbal: gimbal::Stream,
    /// The galvo stroke in flight (several blocks joined).
    pub(in crate::sequencer) galvo: galvo::GalvoStroke,
    /// What the stepper has of the job.
    pub(in crate::sequencer) stepper: stepper::StepperJob,
}

impl DriverJobs {
    /// Nothing in flight (power-up).
    pub(in crate::sequencer) fn new() -> Self {
        Self {
            gimbal: gimbal::Stream::new(),
            galvo: galvo::GalvoStroke::default(),
            stepper: stepper::StepperJob::default(),
        }
    }
}

/// One G-code step for a driver that takes blocks step by step.
#[derive(Debug, Clone, Copy)]
pub(in crate::sequencer) struct DriverStep {
    /// Where it starts, board mm.
    pub(in crate::sequencer) from: PointMm,
    /// Where it ends, board mm.
    pub(in crate::sequencer) to: PointMm,
    /// Feed, mm/min (`None`: rapid).
    pub(in crate::sequencer) feed: Option<f64>,
    /// Laser lit while it moves.
    pub(in crate::sequencer) lit: bool,
    /// It ends a block (arrive within the driver's resolution).
    pub(in crate::sequencer) corner: bool,
}

pub(in crate::sequencer) mod dispatch;
pub(in crate::sequencer) mod galvo;
pub(in crate::sequencer) mod gimbal;
pub(in crate::sequencer) mod stage;
pub(in crate::sequencer) mod stepper;
