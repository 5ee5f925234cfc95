//! The sequencer core: the whole state machine as a pure function of its
//! state and one [`Event`] — `Core::on(state, event) → actions`.
//!
//! No `async`, no I/O and no clock inside: the time and the room in the
//! galvo queue arrive with each event ([`Inputs`]), what the shell reads
//! from the links for a command with the command ([`Readings`]), and
//! everything the core wants done leaves as an [`Action`] written, in
//! order, into an [`ActionSink`]. The shell ([`super::Sequencer`]) applies
//! them; the tests record them. What the status board shows is a view of
//! this state ([`Core::status`]), and so is the dwell deadline
//! ([`Core::dwell_deadline`]): neither can drift from it.
//!
//! Two commands take more than one event, because the shell must await
//! something before their reply: a pattern check runs a few points per
//! [`Event::CheckStep`] (the shell yields in between so the other tasks
//! run, [`Action::Yield`]), and a save waits for the store
//! ([`Action::Save`], then [`Event::Saved`]). The shell feeds nothing else
//! in between; should something else arrive, a pending check is finished
//! at once first, so every command still gets exactly one reply.

use embassy_time::Instant;

use super::faults::ServoFaults;
use super::laser::{LaserEvent, laser_wanted};
use super::run::Run;
use crate::command::Command;
use crate::domain::{Actuator, Aim, AimModel, Aimer, PatternCheck, Target};
use crate::galvo::{GalvoConfig, GalvoEvent, GalvoRequest, RefillTime, ScanPhase};
use crate::log;
use crate::servo::task::{ServoOutcome, ServoRequest};
use crate::settings::{LoadedRecord, RecordError, Settings};
use crate::status::{Activity, Snapshot};
use crate::stepper::{StepperConfig, StepperEvent, StepperRequest};
use crate::text::{ReplyText, reply_text};

/// Something that happened, for the core to act on.
#[derive(Debug, Clone, Copy)]
#[allow(clippy::large_enum_variant)] // No heap: an event is a stack value for one call.
pub enum Event {
    /// A command from the console; its reply closes with exactly one
    /// `ok` / `error:` (after follow-up events for a check or a save).
    Command {
        /// The command.
        command: Command,
        /// What the shell read from the links when it arrived.
        readings: Readings,
    },
    /// The board's stop button: stop, laser off, no reply.
    StopRequest,
    /// The servo task's report (arrival, fault, timeout, recovery).
    Servo(ServoOutcome),
    /// The galvo loop's report.
    Galvo(GalvoEvent),
    /// The stepper task's report.
    Stepper(StepperEvent),
    /// The dwell deadline ([`Core::dwell_deadline`]) passed.
    DwellEnded,
    /// The housekeeping tick (liveness for the watchdog).
    Tick,
    /// Continue the pending pattern check (after [`Action::Yield`]).
    CheckStep,
    /// The result of [`Action::Save`]; `Err` carries a message for the
    /// user.
    Saved(Result<(), &'static str>),
    /// The settings record read at boot, decoded.
    SettingsLoaded(Result<LoadedRecord, RecordError>),
    /// The master laser gate refused the gimbal laser: someone else (the
    /// galvo loop, on an underrun) closed it since the core last did. The
    /// gimbal laser stays dark until the core closes it again.
    GateLost,
    /// A grbl realtime command from the console (`?`, `!`, `~`, 0x18, …).
    Realtime(crate::command::RealtimeRequest),
}

/// What the shell reads from the links when a command arrives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Readings {
    /// The galvo loop's state (all zero when no galvo loop runs).
    pub galvo: GalvoReadout,
    /// Servo angle readings rejected as implausible since boot.
    pub implausible_readings: u32,
}

/// The galvo loop's state and counters, as `galvo status` shows them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GalvoReadout {
    /// Phase after its last half buffer.
    pub phase: ScanPhase,
    /// Points queued after its last half buffer.
    pub queued: usize,
    /// Underruns since boot.
    pub underruns: u32,
    /// Half buffers written since boot.
    pub halves: u32,
    /// The DAC's worst refill, when the board measures it.
    pub refill: Option<RefillTime>,
}

/// What the shell knows just before the core handles an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Inputs {
    /// Now.
    pub now: Instant,
    /// Free slots in the galvo request queue (only the core sends, only
    /// the galvo loop takes: the room can only grow until the core's
    /// requests are applied); `None` when no galvo loop serves the link
    /// (a board without a galvo DAC): galvo commands are refused.
    pub galvo_room: Option<usize>,
    /// The galvo loop's board plans jumps by bisection (`planner seed`;
    /// refused where it does not fit the target's time).
    pub galvo_bisection: bool,
    /// A stepper task serves the stepper link (else `target stepper` is
    /// refused).
    pub stepper_attached: bool,
}

/// Something the core wants done, in order.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// Send a request to the servo task; the newest wins (one it has not
    /// taken yet is dropped).
    Servo(ServoRequest),
    /// Queue a request for the galvo loop; [`GalvoRequest::Stop`] first
    /// drops the queued ones, so it always has room.
    Galvo(GalvoRequest),
    /// New galvo loop parameters (the latest wins).
    ConfigureGalvo(GalvoConfig),
    /// Whether the laser mode lets the galvo light.
    AllowGalvoLaser(bool),
    /// Send a request to the stepper task.
    Stepper(StepperRequest),
    /// New stepper parameters (the latest wins, applied at rest).
    ConfigureStepper(StepperConfig),
    /// Close the master laser gate: dark at once, a new generation (what
    /// anyone computed before stays dark).
    CloseGate,
    /// Shut the master gate: dark at once, same generation (the run may
    /// light again).
    ShutGate,
    /// Switch the gimbal laser; on only through the master gate (when it
    /// refuses, the shell answers [`Event::GateLost`]).
    GimbalLaser(bool),
    /// The power the gimbal laser runs at while lit (sent before the
    /// [`Action::GimbalLaser`] that lights it, and whenever it changes
    /// while lit).
    GimbalPower(super::LaserPower),
    /// Tell the laser switch about an event that decides when a laser may
    /// be lit ([`super::LaserSwitch::note`]).
    Note(LaserEvent<'static>),
    /// A line to the console.
    Line(Line),
    /// Save the settings ([`Core::settings`]); answer with
    /// [`Event::Saved`].
    Save,
    /// Let the other tasks run, then send [`Event::CheckStep`].
    Yield,
}

/// A console line.
#[derive(Debug, Clone, PartialEq)]
pub enum Line {
    /// A data line of the current reply.
    Data(ReplyText),
    /// An unsolicited notice.
    Notice(ReplyText),
    /// Closes the reply: `ok`.
    Ok,
    /// Closes the reply: `error: <reason>`.
    Error(ReplyText),
    /// Closes a G-code or `$` line's reply: grbl's `error:N`.
    GrblError(crate::grbl::GrblError),
}

/// Where the core writes its actions (the shell applies them at once, a
/// test records them).
pub trait ActionSink {
    /// Takes the next action.
    fn act(&mut self, action: Action);
}

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
    /// A save in flight, answered by [`Event::Saved`].
    Save,
}

/// What follows a pattern check.
#[derive(Debug, Clone, Copy)]
#[allow(clippy::large_enum_variant)] // No heap: held in the core's state.
pub(super) enum AfterCheck {
    /// `pattern`: start it (or refuse it).
    Start(super::run::Start),
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
    pub(super) laser_power: super::LaserPower,
    /// The gate was closed by someone else since the core last closed it.
    pub(super) gate_lost: bool,
    /// Housekeeping ticks (liveness).
    pub(super) heartbeat: u32,
    pub(super) pending: Option<Pending>,
    /// Inputs of the event being handled (the galvo room counts down as
    /// jobs are sent).
    pub(super) inputs: Inputs,
    /// The grbl session: G-code parser, motion queue, grbl settings.
    pub(super) gcode: super::gcode::Gcode,
}

impl Core {
    /// Idle, default settings, gimbal, laser off; booted at `now`.
    #[inline(never)]
    pub fn new(now: Instant) -> Self {
        Self {
            settings: Settings::default(),
            model: AimModel::Exact,
            aimer: Settings::default().aimer(AimModel::Exact),
            actuator: Actuator::Gimbal,
            booted_at: now,
            run: None,
            next_seq: 0,
            faults: ServoFaults::default(),
            last_aim: None,
            measured: None,
            laser_on: false,
            laser_power: super::LaserPower::FULL,
            gate_lost: false,
            heartbeat: 0,
            pending: None,
            inputs: Inputs {
                now,
                galvo_room: None,
                galvo_bisection: false,
                stepper_attached: false,
            },
            gcode: super::gcode::Gcode::new(),
        }
    }

    /// Handles `event`, writing what is to be done into `out`.
    pub fn on(&mut self, inputs: Inputs, event: Event, out: &mut dyn ActionSink) {
        self.inputs = inputs;
        if !matches!(event, Event::CheckStep) {
            // Not what the shell does; should it happen, the command in
            // check still gets its reply first.
            self.check_step(usize::MAX, out);
        }
        match event {
            Event::Command { command, readings } => self.command(command, &readings, out),
            Event::StopRequest => self.stop("stop button", out),
            Event::Servo(outcome) => self.servo_outcome(outcome, out),
            Event::Galvo(event) => self.galvo_event(event, out),
            Event::Stepper(event) => self.stepper_event(event, out),
            Event::DwellEnded => self.dwell_ended(out),
            Event::Tick => self.heartbeat = self.heartbeat.wrapping_add(1),
            Event::CheckStep => self.check_step(super::commands::CHECKS_PER_STEP, out),
            Event::Saved(result) => self.saved(result, out),
            Event::SettingsLoaded(loaded) => self.settings_loaded(loaded, out),
            Event::GateLost => self.gate_lost = true,
            Event::Realtime(request) => self.grbl_realtime(request, out),
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
        self.gcode_deadline_or(self.run.and_then(|r| r.dwell_until))
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
        let servo_blocked =
            !self.actuator.uses_stepper() && self.faults.gimbal_laser_blocked(yaw, pitch, phase);
        let wanted = (self.actuator.uses_gimbal() || self.actuator.uses_stepper())
            && (laser_wanted(self.settings.laser_mode, phase, servo_blocked)
                || self.gcode_gimbal_lit())
            && !self.gate_lost;
        // Full power for the product's patterns; G-code's S, overrides
        // and M4 speed scaling otherwise (dark at 0: M4 at rest).
        let power = self.gcode_gimbal_power();
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

    /// Closes the master laser gate (laser dark from now on, also samples
    /// the galvo DAC already holds) and stops the galvo loop.
    pub(super) fn close_gate(&mut self, out: &mut dyn ActionSink) {
        out.act(Action::CloseGate);
        self.gate_lost = false;
        self.stop_galvo(out);
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
        out.act(Action::Line(Line::Error(reply_text(format_args!(
            "{reason}"
        )))));
    }
}

#[cfg(test)]
mod proptests;
#[cfg(test)]
mod tests;
