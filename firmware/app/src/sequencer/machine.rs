//! The sequencer core: the whole state machine as a pure function of its
//! state and one [`Event`] — `Core::on(state, event) → actions`.
//!
//! No `async`, no I/O and no clock inside: the time and the room in the
//! galvo queue arrive with each event ([`Inputs`]), what the shell reads
//! from the links for a command with the command ([`Readings`]), and
//! everything the core wants done leaves as an [`Action`] written, in
//! order, into an [`ActionSink`]. The shell ([`crate::sequencer::Sequencer`]) applies
//! them; the tests record them. What the status board shows is a view of
//! this state ([`Core::status`]), and so is the dwell deadline
//! ([`Core::dwell_deadline`]): neither can drift from it.
//!
//! Two commands take more than one event, because the shell must await
//! something before their reply: a pattern check runs a few points per
//! [`Event::CheckStep`] (the shell yields in between so the other tasks
//! run, [`Action::Yield`]), and a save waits for the store
//! ([`Action::Save`], then [`Event::Saved`]; a preset's likewise). The shell feeds nothing else
//! in between; should something else arrive, a pending check is finished
//! at once first, so every command still gets exactly one reply.

use crate::domain::{Actuator, Aim, AimModel, Aimer, PatternCheck, Target};
use crate::log;
use crate::sequencer::drivers::{Driver, Drivers, galvo, stepper};
use crate::sequencer::faults::ServoFaults;
use crate::sequencer::gcode::context::Session;
use crate::sequencer::gcode::proven::ProvenReach;
use crate::sequencer::gcode::reach::ReachCheck;
pub use crate::sequencer::io::{Action, ActionSink, Event, GalvoReadout, Inputs, Line, Readings};
use crate::sequencer::laser::laser_wanted;
use crate::sequencer::run::Run;
use crate::settings::{LoadedRecord, RecordError, Settings};
use crate::status::{Activity, Snapshot};
use crate::text::reply_text;
use embassy_time::Instant;

/// Points a pattern check aims at per executor step. One gimbal IK point
/// is ~170 µs of soft-float on the target; with the first point of the
/// run aimed in the last step, a step aims at no more than four (~0.7 ms).
pub(super) const CHECKS_PER_STEP: usize = 3;

/// A command waiting for a follow-up event before its reply.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)] // No heap: held in the core's state.
pub(super) enum Pending {
    /// A pattern check, a few points per [`Event::CheckStep`].
    Check {
        /// Where it is.
        check: PatternCheck,
        /// What follows when it is done.
        then: AfterCheck,
    },
    /// A save (of the settings or a preset) in flight, answered by
    /// [`Event::Saved`].
    Save,
    /// A preset call waiting for the store, answered by
    /// [`Event::PresetLoaded`] for that preset.
    Preset(u8),
    /// A servo bus set-up job in flight, answered by its
    /// `ServoOutcome::Bus` reports.
    ServoBus {
        /// Its request number.
        seq: u32,
    },
}

/// What follows a pattern check.
#[derive(Debug, Clone, Copy)]
#[allow(clippy::large_enum_variant)] // No heap: held in the core's state.
pub(super) enum AfterCheck {
    /// `pattern`: start it (or refuse it).
    Start(crate::sequencer::run::Start),
    /// `set` during a run: keep the new settings (or go back to `before`).
    KeepSettings {
        /// The settings before the `set`.
        before: Settings,
    },
}

/// The sequencer's state. Create with [`Core::new`]; feed it events with
/// [`Core::on`].
#[derive(Debug, Clone)]
pub struct Core {
    pub(super) settings: Settings,
    pub(super) model: AimModel,
    /// The geometry of `settings` and `model`, rebuilt when either changes
    /// ([`Core::geometry_changed`]).
    pub(super) aimer: Aimer,
    /// Per driver, the part of the board proven reachable with `settings`
    /// (the soft-limit check's fast path), proven again with `aimer`.
    pub(super) reach: ProvenReach,
    /// Which actuator(s) draw.
    pub(super) actuator: Actuator,
    pub(super) booted_at: Instant,
    /// The active pattern or goto.
    pub(super) run: Option<Run>,
    /// Request number of the last servo move or galvo job.
    pub(super) next_seq: u32,
    /// Servos known dead, and whether the gimbal laser waits for an arrival.
    pub(super) faults: ServoFaults,
    /// Last aim sent to the servos.
    pub(super) last_aim: Option<(Target, Aim)>,
    /// Last measured servo angles, 0.1°.
    pub(super) measured: Option<(i16, i16)>,
    /// Whether the gimbal laser is on.
    pub(super) laser_on: bool,
    /// The power the gimbal laser runs at while on.
    pub(super) laser_power: crate::sequencer::laser::LaserPower,
    /// The gate was closed by someone else since the core last closed it.
    pub(super) gate_lost: bool,
    /// Housekeeping ticks (liveness).
    pub(super) heartbeat: u32,
    pub(super) pending: Option<Pending>,
    /// Inputs of the event being handled (the galvo room counts down as
    /// jobs are sent).
    pub(super) inputs: Inputs,
    /// The grbl session: G-code parser, motion queue, grbl settings.
    pub(super) gcode: crate::sequencer::gcode::GcodeSession,
    /// What each actuator driver keeps of the G-code job.
    pub(super) jobs: crate::sequencer::drivers::DriverJobs,
    /// The stepper task homes (`home` or `$H` sent, its end not reported).
    pub(super) stepper_homing: bool,
    /// The laser controls' state (`None`: the board has none).
    pub(super) controls: Option<crate::laser_controls::ControlsView>,
}

impl Core {
    /// Idle, default settings, gimbal, laser off; booted at `now`.
    #[inline(never)]
    pub fn new(now: Instant) -> Self {
        Self {
            settings: Settings::default(),
            model: AimModel::Exact,
            aimer: Settings::default().aimer(AimModel::Exact),
            reach: ProvenReach::UNPROVEN,
            actuator: Actuator::Gimbal,
            booted_at: now,
            run: None,
            next_seq: 0,
            faults: ServoFaults::default(),
            last_aim: None,
            measured: None,
            laser_on: false,
            laser_power: crate::sequencer::laser::LaserPower::FULL,
            gate_lost: false,
            heartbeat: 0,
            pending: None,
            inputs: Inputs {
                now,
                galvo_room: None,
                galvo_bisection: false,
                stepper_attached: false,
            },
            gcode: crate::sequencer::gcode::GcodeSession::new(),
            jobs: crate::sequencer::drivers::DriverJobs::new(),
            stepper_homing: false,
            controls: None,
        }
    }

    /// Handles `event`, writing what is to be done into `out`.
    pub fn on(&mut self, inputs: Inputs, event: Event, out: &mut dyn ActionSink) {
        self.inputs = inputs;
        self.reach = (self.reach).or_prove(|| ReachCheck::new(&self.settings, &self.aimer).prove());
        if !matches!(event, Event::CheckStep) {
            // Not what the shell does; should it happen, the command in
            // check still gets its reply first.
            self.check_step(usize::MAX, out);
        }
        match event {
            Event::Command { command, readings } => self.command(command, &readings, out),
            Event::StopRequest => self.stop(self.stop_request_cause(), out),
            Event::Servo(outcome) => self.servo_outcome(outcome, out),
            Event::Galvo(event) => self.galvo_event(event, out),
            Event::Stepper(event) => self.stepper_event(event, out),
            Event::DwellEnded => {
                self.dwell_finished(out);
                self.session().dwell_check(out);
            }
            Event::Tick => self.heartbeat = self.heartbeat.wrapping_add(1),
            Event::CheckStep => self.check_step(CHECKS_PER_STEP, out),
            Event::Saved(result) => self.saved(result, out),
            Event::PresetLoaded { n, point } => self.preset_loaded(n, point, out),
            Event::SettingsLoaded(loaded) => self.settings_loaded(loaded, out),
            Event::GateLost => self.gate_lost = true,
            Event::Realtime(request) => self.session().realtime(request, out),
        }
        // A command in check has not changed anything yet.
        if !matches!(self.pending, Some(Pending::Check { .. })) {
            self.apply_laser(out);
        }
    }

    /// Current settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// When the current dwell ends (`None`: no dwell running).
    pub fn dwell_deadline(&self) -> Option<Instant> {
        let run_deadline = self.run.and_then(|r| r.dwell_until);
        let drivers = (&self.settings, &self.jobs, self.drivers());
        (self.gcode).deadline_or(run_deadline, drivers, self.inputs.now)
    }

    /// Whether the gimbal laser is on.
    pub fn laser_on(&self) -> bool {
        self.laser_on
    }

    /// What the status board shows (LEDs, watchdog, simulator, `status`).
    pub fn status(&self) -> Snapshot {
        let run = self.run;
        Snapshot {
            activity: match run {
                None if !self.gcode.motion.is_idle() => Activity::Gcode,
                None if self.stepper_homing => Activity::Homing,
                None => Activity::Idle,
                Some(r) => match r.kind.pattern() {
                    Some(p) => Activity::Pattern(p),
                    None => Activity::Goto,
                },
            },
            phase: run.map(|r| r.phase),
            point_index: run.map(|r| r.index),
            pass: run.map_or(0, |r| r.pass),
            target: self.last_aim,
            laser_on: self.laser_on,
            faulty_servo: self.faults.first_dead(),
            heartbeat: self.heartbeat,
        }
    }

    /// The settings read at boot (defaults, with a warning, when the record
    /// is missing, old or corrupt); the galvo loop starts with them.
    fn settings_loaded(
        &mut self,
        loaded: Result<LoadedRecord, RecordError>,
        out: &mut dyn ActionSink,
    ) {
        self.settings = match loaded {
            Ok(loaded) => {
                log::info!(
                    "settings loaded from flash ({:?} layout; {} unknown entries skipped, {} parameters defaulted)",
                    loaded.layout,
                    loaded.unknown,
                    loaded.defaulted
                );
                loaded.settings
            }
            Err(RecordError::Missing) => {
                log::info!("no saved settings, using defaults");
                Settings::default()
            }
            Err(e) => {
                log::warning!("saved settings unusable ({:?}), using defaults", e);
                Settings::default()
            }
        };
        self.geometry_changed();
        self.configure_galvo(out);
        self.configure_stepper(out);
    }

    /// Rebuilds the geometry the run aims with after the settings or the
    /// model changed.
    pub(super) fn geometry_changed(&mut self) {
        self.aimer = self.settings.aimer(self.model);
        self.reach = ReachCheck::new(&self.settings, &self.aimer).prove();
        self.jobs.gimbal.geometry_changed();
    }

    /// Switches the gimbal laser to what the state calls for.
    fn apply_laser(&mut self, out: &mut dyn ActionSink) {
        let phase = self.run.map(|r| r.phase);
        let (yaw, pitch) = (self.settings.yaw.id, self.settings.pitch.id);
        // The galvo's laser is switched per sample by the galvo loop; this
        // is the gimbal's. Dark once the gate was closed by someone else
        // (a galvo underrun) until the run is stopped or restarted.
        // The stepper pan/tilt carries the gimbal's laser; no servo
        // blocks it.
        let drivers = self.drivers();
        let servo_blocked = drivers.any(Driver::needs_servos)
            && self.faults.gimbal_laser_blocked(yaw, pitch, phase);
        let wanted = drivers.any(Driver::carries_laser_pin)
            && (laser_wanted(self.settings.laser_mode, phase, servo_blocked)
                || self.gcode.gimbal_lit(&self.settings))
            && !self.gate_lost;
        // Full power for the product's patterns; G-code's S, overrides
        // and M4 speed scaling otherwise (dark at 0: M4 at rest).
        let power = self.gcode.gimbal_power(&self.settings, &self.jobs, drivers);
        let wanted = wanted && power.is_on();
        if wanted && power != self.laser_power {
            self.laser_power = power;
            out.act(Action::GimbalPower(power));
        }
        if wanted != self.laser_on {
            self.laser_on = wanted;
            out.act(Action::GimbalLaser(wanted));
        }
    }

    /// The G-code session at work on this event, with what it moves on.
    pub(super) fn session(&mut self) -> Session<'_> {
        let door = self.door_substate();
        Session {
            gcode: &mut self.gcode,
            jobs: &mut self.jobs,
            settings: &mut self.settings,
            aimer: &self.aimer,
            reach: self.reach,
            inputs: &mut self.inputs,
            next_seq: &mut self.next_seq,
            run: &mut self.run,
            last_aim: &mut self.last_aim,
            measured: self.measured,
            drivers: Drivers::of(self.actuator),
            gate_lost: &mut self.gate_lost,
            stepper_homing: &mut self.stepper_homing,
            laser: self.laser_on.then_some(self.laser_power),
            door,
        }
    }

    /// Closes the master laser gate (laser dark from now on, also samples
    /// the galvo DAC already holds) and stops the galvo loop.
    pub(super) fn close_gate(&mut self, out: &mut dyn ActionSink) {
        self.session().close_gate(out);
    }

    /// The driver(s) that draw.
    pub(super) fn drivers(&self) -> Drivers {
        Drivers::of(self.actuator)
    }

    /// Sends the galvo loop the parameters of the settings ([`galvo::points::configure`]).
    pub(super) fn configure_galvo(&mut self, out: &mut dyn ActionSink) {
        galvo::points::configure(&self.settings, self.run, &self.inputs, out);
    }

    /// Sends the stepper task the parameters of the settings.
    pub(super) fn configure_stepper(&mut self, out: &mut dyn ActionSink) {
        let junction = &mut self.gcode.stepper_junction_deg;
        stepper::points::configure(&self.settings, junction, out);
    }

    /// Queues a notice line.
    pub(super) fn notify(&self, out: &mut dyn ActionSink, args: core::fmt::Arguments<'_>) {
        out.act(Action::Line(Line::Notice(reply_text(args))));
    }

    /// Queues a data line of the current reply.
    pub(super) fn data(&self, out: &mut dyn ActionSink, args: core::fmt::Arguments<'_>) {
        out.act(Action::Line(Line::Data(reply_text(args))));
    }

    /// Closes the current reply with `ok`.
    pub(super) fn ok(&self, out: &mut dyn ActionSink) {
        out.act(Action::Line(Line::Ok));
    }

    /// Closes the current reply with `error: <reason>`.
    pub(super) fn error(&self, out: &mut dyn ActionSink, reason: impl core::fmt::Display) {
        let text = reply_text(format_args!("{reason}"));
        out.act(Action::Line(Line::Error(text)));
    }
}

#[cfg(test)]
mod proptests;
#[cfg(test)]
mod tests;
