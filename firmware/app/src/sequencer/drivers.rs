//! The actuator drivers: the gimbal (FashionStar servos), the galvo (DAC
//! loop) and the stepper (STEP/DIR) behind one interface, and the target
//! selection ([`Drivers`]: the driver(s) that draw, `target both`
//! included).
//!
//! Everything the core and the G-code session ask an actuator goes
//! through here: whether it reaches a board point, what it does with a
//! point of a pattern ([`Core::driver_aim`]) and with a G-code step
//! ([`Core::driver_step`]), how it is re-aimed, reset and homed, what
//! laser it carries and how that follows its speed, and how fast it may
//! mark. Enum dispatch: a [`Driver`] is one byte, each question one
//! `match`, nothing allocated. What a driver does itself lives in its
//! files (gimbal: `run.rs` point moves, `gcode_step.rs`/`gcode_stream`;
//! galvo: `galvo.rs`, `gcode_galvo`; stepper: `stepper.rs`,
//! `gcode_stepper.rs`). A new actuator is a new variant here, its
//! answers in these `match`es, its files, and its link in the shell.

use crate::domain::{Actuator, PointCm, Target};
use crate::grbl::PointMm;
use crate::settings::Settings;

use super::machine::{ActionSink, Core};

/// One actuator driver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Driver {
    /// The servo gimbal.
    Gimbal,
    /// The stepper pan/tilt.
    Stepper,
    /// The two-mirror galvo scanner.
    Galvo,
}

/// How a pattern's path runs on the drivers that draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum PathRun {
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
pub(super) enum Arrival {
    /// The move's arrival (servo outcome or stepper at rest).
    Move,
    /// The job's end (galvo `done`).
    Job,
}

impl Driver {
    /// Whether it moves the gimbal's servos (a dead servo refuses and
    /// stops it, and darkens its laser).
    pub(super) const fn needs_servos(self) -> bool {
        matches!(self, Driver::Gimbal)
    }

    /// Whether it carries the gimbal laser output, which the sequencer
    /// switches (the galvo's laser is switched per sample by its loop).
    pub(super) const fn carries_laser_pin(self) -> bool {
        matches!(self, Driver::Gimbal | Driver::Stepper)
    }

    /// Whether a G-code line is split into path steps (`path.step_cm`)
    /// for it (the others take a line whole).
    pub(super) const fn steps_lines(self) -> bool {
        matches!(self, Driver::Gimbal)
    }

    /// Whether `$H` homes it with switches (the others go to the origin).
    pub(super) const fn homes_with_switches(self) -> bool {
        matches!(self, Driver::Stepper)
    }

    /// Whether its M4 power follows a speed it does not report by events
    /// (re-applied every stream period while it moves lit).
    pub(super) const fn polls_speed(self) -> bool {
        matches!(self, Driver::Stepper)
    }

    /// Whether its laser power is on/off at the programmed S (reported
    /// as such), rather than the level the laser output runs at.
    pub(super) const fn reports_programmed_power(self) -> bool {
        matches!(self, Driver::Galvo)
    }

    /// What a pattern's point waits for on it.
    pub(super) const fn arrival(self) -> Arrival {
        match self {
            Driver::Gimbal | Driver::Stepper => Arrival::Move,
            Driver::Galvo => Arrival::Job,
        }
    }

    /// Its highest marking feed, mm/min (unlimited: infinity).
    pub(super) fn feed_cap_mm_min(self, settings: &Settings) -> f64 {
        match self {
            Driver::Galvo => settings.galvo.mark_speed_mm_s * 60.0,
            Driver::Gimbal | Driver::Stepper => f64::INFINITY,
        }
    }
}

/// The driver(s) that draw: the target selection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Drivers(Actuator);

impl Drivers {
    /// The driver(s) of `target <actuator>`.
    pub(super) const fn of(actuator: Actuator) -> Self {
        Drivers(actuator)
    }

    /// The drivers that draw, in the order a point is sent to them.
    pub(super) fn iter(self) -> impl Iterator<Item = Driver> {
        let drivers: &'static [Driver] = match self.0 {
            Actuator::Gimbal => &[Driver::Gimbal],
            Actuator::Galvo => &[Driver::Galvo],
            Actuator::Both => &[Driver::Gimbal, Driver::Galvo],
            Actuator::Stepper => &[Driver::Stepper],
        };
        drivers.iter().copied()
    }

    /// Whether any driver that draws answers `question` with yes.
    pub(super) fn any(self, question: impl Fn(Driver) -> bool) -> bool {
        self.iter().any(question)
    }

    /// Whether several drivers draw together, step by step (`target
    /// both`): no driver runs ahead with its own planning.
    pub(super) fn lockstep(self) -> bool {
        self.iter().count() > 1
    }

    /// Whether the gimbal alone draws G-code: it streams the blocks
    /// through its look-ahead plan.
    pub(super) fn gimbal_streams(self) -> bool {
        self.0 == Actuator::Gimbal
    }

    /// Whether the stepper draws G-code: blocks are handed over to its
    /// task whole.
    pub(super) fn hands_over_blocks(self) -> bool {
        self.0 == Actuator::Stepper
    }

    /// The lowest marking feed cap of the drivers that draw, mm/min.
    pub(super) fn feed_cap_mm_min(self, settings: &Settings) -> f64 {
        self.iter()
            .map(|d| d.feed_cap_mm_min(settings))
            .fold(f64::INFINITY, f64::min)
    }

    /// How a pattern's path runs; `exact`: the exact aiming model.
    pub(super) fn path_run(self, exact: bool) -> PathRun {
        match self.0 {
            Actuator::Stepper if exact => PathRun::Traced,
            Actuator::Gimbal | Actuator::Stepper => PathRun::Points,
            Actuator::Galvo => PathRun::Marked,
            Actuator::Both => PathRun::Refused,
        }
    }

    /// Whether `target <actuator>` can be served: `Err` with the reason
    /// when its link is not (the gimbal's always is).
    pub(super) fn check_attached(
        actuator: Actuator,
        galvo_attached: bool,
        stepper_attached: bool,
    ) -> Result<(), &'static str> {
        match actuator {
            Actuator::Gimbal => Ok(()),
            Actuator::Stepper if stepper_attached => Ok(()),
            Actuator::Stepper => Err(super::commands::NO_STEPPER),
            Actuator::Galvo | Actuator::Both if galvo_attached => Ok(()),
            Actuator::Galvo | Actuator::Both => Err(super::commands::NO_GALVO),
        }
    }
}

impl Core {
    /// The driver(s) that draw.
    pub(super) fn drivers(&self) -> Drivers {
        Drivers::of(self.actuator)
    }

    /// Whether `driver` reaches board point `p` (cm).
    pub(super) fn driver_reaches(&self, driver: Driver, p: PointCm) -> bool {
        match driver {
            Driver::Gimbal => self.aimer.aim(p).is_ok(),
            Driver::Galvo => self.aimer.galvo_in_range(p),
            Driver::Stepper => self.stepper_reaches(p),
        }
    }

    /// Whether every driver that draws reaches board point `p` (cm).
    pub(super) fn drivers_reach(&self, p: PointCm) -> bool {
        self.drivers().iter().all(|d| self.driver_reaches(d, p))
    }

    /// Aims `driver` at a pattern's current point `target` (`approach`:
    /// travel, dark); `false` when it could not (the run stopped).
    pub(super) fn driver_aim(
        &mut self,
        driver: Driver,
        target: Target,
        approach: bool,
        out: &mut dyn ActionSink,
    ) -> bool {
        match driver {
            Driver::Gimbal => self.begin_gimbal_move(target, out),
            Driver::Stepper => self.begin_stepper_move(target, approach, out),
            Driver::Galvo => self.begin_galvo_point(target, out),
        }
    }

    /// The point of the running pattern is re-aimed (`model`): a driver
    /// whose jobs queue drops the one running first (a servo move
    /// supersedes the last by itself).
    pub(super) fn drivers_supersede(&mut self, out: &mut dyn ActionSink) {
        if self.drivers().any(|d| d.arrival() == Arrival::Job) {
            self.stop_galvo(out);
        }
    }

    /// grbl's soft reset: a driver that can drop its motion at once does
    /// (the stepper's steps are killed; the position is then uncertain);
    /// the stop that follows brakes the others.
    pub(super) fn drivers_reset(&mut self, out: &mut dyn ActionSink) {
        if self.drivers().hands_over_blocks() {
            out.act(super::Action::Stepper(crate::stepper::StepperRequest::Halt));
        }
    }

    /// Sends the G-code step from `from` to `to` (`feed` mm/min, `None`:
    /// rapid; `lit`; `corner`: it ends a block) to `driver`; its request
    /// number, `None` when it could not be sent (the session stopped).
    pub(super) fn driver_step(
        &mut self,
        driver: Driver,
        step: DriverStep,
        out: &mut dyn ActionSink,
    ) -> Option<u32> {
        match driver {
            Driver::Gimbal => {
                self.gcode_servo_move(step.from, step.to, step.feed, step.corner, out)
            }
            Driver::Galvo => self.gcode_galvo_send(step.from, step.to, step.feed, step.lit, out),
            // Blocks are handed over whole (`gcode_stepper_send`).
            Driver::Stepper => None,
        }
    }
}

/// One G-code step for a driver that takes blocks step by step.
#[derive(Debug, Clone, Copy)]
pub(super) struct DriverStep {
    /// Where it starts, board mm.
    pub(super) from: PointMm,
    /// Where it ends, board mm.
    pub(super) to: PointMm,
    /// Feed, mm/min (`None`: rapid).
    pub(super) feed: Option<f64>,
    /// Laser lit while it moves.
    pub(super) lit: bool,
    /// It ends a block (arrive within the driver's resolution).
    pub(super) corner: bool,
}
