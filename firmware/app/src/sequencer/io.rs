//! What goes into the sequencer core ([`Event`], with its [`Inputs`] and
//! [`Readings`]) and what comes out of it ([`Action`]s into an
//! [`ActionSink`], console [`Line`]s).

use crate::command::Command;
use crate::domain::PointCm;
use crate::galvo::{GalvoConfig, GalvoEvent, GalvoRequest, RefillTime, ScanPhase};
use crate::sequencer::laser::LaserEvent;
use crate::servo::task::{ServoOutcome, ServoRequest};
use crate::settings::{LoadedRecord, RecordError};
use crate::stepper::{StepperConfig, StepperEvent, StepperRequest};
use crate::text::ReplyText;
use embassy_time::Instant;

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
    /// The dwell deadline ([`Core::dwell_deadline`](crate::sequencer::machine::Core::dwell_deadline)) passed.
    DwellEnded,
    /// The housekeeping tick (liveness for the watchdog).
    Tick,
    /// Continue the pending pattern check (after [`Action::Yield`]).
    CheckStep,
    /// The result of [`Action::Save`] or [`Action::SavePreset`]; `Err`
    /// carries a message for the user.
    Saved(Result<(), &'static str>),
    /// The answer to [`Action::LoadPreset`]: preset `n`'s board point, if
    /// one is saved.
    PresetLoaded {
        /// The preset's number.
        n: u8,
        /// Its board point, cm.
        point: Option<PointCm>,
    },
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
    /// Arm the laser controls (their manual reset) with this emission
    /// indicator delay, ms.
    ArmLaser {
        /// The indicator's lead before emission becomes possible, ms.
        delay_ms: u32,
    },
    /// Switch the gimbal laser; on only through the master gate (when it
    /// refuses, the shell answers [`Event::GateLost`]).
    GimbalLaser(bool),
    /// The power the gimbal laser runs at while lit (sent before the
    /// [`Action::GimbalLaser`] that lights it, and whenever it changes
    /// while lit).
    GimbalPower(crate::sequencer::laser::LaserPower),
    /// Tell the laser switch about an event that decides when a laser may
    /// be lit ([`crate::sequencer::laser::LaserSwitch::note`]).
    Note(LaserEvent<'static>),
    /// A line to the console.
    Line(Line),
    /// Save the settings ([`Core::settings`](crate::sequencer::machine::Core::settings)); answer with
    /// [`Event::Saved`].
    Save,
    /// Save board point `point` as preset `n` (`None`: clear it) in the
    /// settings store; answer with [`Event::Saved`].
    SavePreset {
        /// The preset's number, 1–255.
        n: u8,
        /// Its board point, cm (`None`: cleared).
        point: Option<PointCm>,
    },
    /// Read preset `n` from the settings store; answer with
    /// [`Event::PresetLoaded`].
    LoadPreset(u8),
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
    /// A grbl push message (`ALARM:N`): never the command in flight's.
    Push(ReplyText),
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
