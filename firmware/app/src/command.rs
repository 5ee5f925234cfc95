//! The command channel: the one path from the command line to the rest of
//! the firmware, and the reply path back.
//!
//! The console task parses a line into a [`Command`], sends it on
//! [`CommandLink::commands`] and waits until its reply is closed; the
//! sequencer task receives commands (also while a pattern runs, so a new
//! command preempts it) and answers each with zero or more data lines and
//! exactly one closing `ok` / `error:`, queued on [`CommandLink::outbound`]
//! without ever waiting for the host (the console's writer sends them).

use core::fmt;
use core::sync::atomic::{AtomicBool, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;

use crate::domain::{Actuator, AimModel, Pattern, PointCm};
use crate::grbl::realtime::Realtime;
use crate::outbound::{LineKind, Origin, Outbound};

mod help;
mod pelco_status;
mod reply;
use crate::settings::{JumpPlanner, LaserMode, ParamSpec};
use crate::text::{ReplyText, Shortest};
pub use help::HELP_LINES;
pub use pelco_status::PelcoStatus;
pub use reply::Reply;

/// A parsed, validated command for the sequencer.
#[derive(Clone, Copy)]
pub enum Command {
    /// List the commands.
    Help,
    /// Firmware version and build.
    Version,
    /// Home the stepper pan/tilt on its limit switches.
    Home,
    /// Uptime, build and current state.
    Status,
    /// Run a pattern, repeating until stopped unless `once`.
    Pattern {
        /// What to run.
        pattern: Pattern,
        /// Run a single pass.
        once: bool,
    },
    /// Stop whatever runs; laser off.
    Stop,
    /// The laser controls' manual reset: with the interlock closed and the
    /// key on, the emission indicator comes on and the laser may emit
    /// after `laser.emission_delay_s`.
    Arm,
    /// Aim at a board point and hold it.
    Goto(PointCm),
    /// Aim at a grid point and hold it.
    Grid {
        /// Column index.
        xi: i8,
        /// Row index.
        yi: i8,
    },
    /// Laser mode.
    Laser(LaserMode),
    /// Report every laser change and laser-deciding sequencer event as a
    /// `[trace …]` notice (on) or not (off): what `cargo xtask hil` checks
    /// on a real board.
    Trace(bool),
    /// Kinematic model.
    Model(AimModel),
    /// Set a parameter.
    Set {
        /// Which.
        param: &'static ParamSpec,
        /// New value (range-checked again by the sequencer).
        value: f64,
    },
    /// Read a parameter.
    Get(&'static ParamSpec),
    /// List every parameter.
    Params,
    /// Store the parameters in flash.
    Save,
    /// Choose the actuator(s).
    Target(Actuator),
    /// Choose the galvo jump planner.
    Planner(JumpPlanner),
    /// Galvo loop state.
    GalvoStatus,
    /// A G-code or `$` line for the grbl layer (answered `ok` once its
    /// motion is queued, `error:N` when refused).
    Grbl(GrblLine),
    /// Servo bus set-up (refused while something runs).
    Servo(ServoSetup),
    /// A preset: a board point kept in the settings store (also PELCO's).
    Preset(PresetCommand),
}

/// The preset commands (`preset …`, PELCO's set / clear / go to preset).
/// Presets are numbered 1–255 and hold a board point (cm), the same spot
/// whichever actuator aims; setting and clearing write the settings
/// store at once (no `save`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PresetCommand {
    /// `preset set <n>`: the spot's board point (the last one aimed)
    /// becomes preset n.
    Set(u8),
    /// `preset clear <n>`: forget preset n.
    Clear(u8),
    /// `preset goto <n>`: aim at preset n and hold it, as `goto`.
    Goto(u8),
}

impl fmt::Display for PresetCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            PresetCommand::Set(n) => write!(f, "preset set {n}"),
            PresetCommand::Clear(n) => write!(f, "preset clear {n}"),
            PresetCommand::Goto(n) => write!(f, "preset goto {n}"),
        }
    }
}

/// The servo bus set-up commands (`servo …`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoSetup {
    /// `servo scan`: every id answering, with angle, voltage, temperature.
    Scan,
    /// `servo ping <id>`.
    Ping(u8),
    /// `servo id <id> <new> [confirm]`: give the one servo on the bus a
    /// new id (without `confirm`: say what would be done, change nothing).
    SetId {
        /// Its id now.
        id: u8,
        /// Its new id (0–254).
        new_id: u8,
        /// `confirm` was given.
        confirmed: bool,
    },
    /// `servo zero <id>`: the servo's angle now becomes the `zero_deg` of
    /// the axis with that id.
    Zero(u8),
}

impl fmt::Display for ServoSetup {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            ServoSetup::Scan => f.write_str("servo scan"),
            ServoSetup::Ping(id) => write!(f, "servo ping {id}"),
            ServoSetup::SetId {
                id,
                new_id,
                confirmed,
            } => write!(
                f,
                "servo id {id} {new_id}{}",
                if confirmed { " confirm" } else { "" }
            ),
            ServoSetup::Zero(id) => write!(f, "servo zero {id}"),
        }
    }
}

/// Longest accepted command line, bytes (excluding the terminator).
pub const MAX_LINE_LEN: usize = 128;

/// A G-code or `$` line as the console assembled it: printable ASCII, at
/// most [`MAX_LINE_LEN`] bytes (a plain array, so [`Command`] stays `Copy`).
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct GrblLine {
    bytes: [u8; MAX_LINE_LEN],
    len: u8,
}

impl GrblLine {
    /// The line `text`; `None` when longer than [`MAX_LINE_LEN`] bytes.
    pub fn new(text: &str) -> Option<Self> {
        let mut bytes = [0u8; MAX_LINE_LEN];
        bytes
            .get_mut(..text.len())?
            .copy_from_slice(text.as_bytes());
        Some(Self {
            bytes,
            len: u8::try_from(text.len()).ok()?,
        })
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        let bytes = self.bytes.get(..usize::from(self.len)).unwrap_or(&[]);
        core::str::from_utf8(bytes).unwrap_or("")
    }
}

impl Command {
    /// The command's name, for logs.
    pub fn name(&self) -> &'static str {
        match self {
            Command::Help => "help",
            Command::Version => "version",
            Command::Home => "home",
            Command::Status => "status",
            Command::Pattern { .. } => "pattern",
            Command::Stop => "stop",
            Command::Arm => "arm",
            Command::Goto(_) => "goto",
            Command::Grid { .. } => "grid",
            Command::Laser(_) => "laser",
            Command::Trace(_) => "trace",
            Command::Model(_) => "model",
            Command::Set { .. } => "set",
            Command::Get(_) => "get",
            Command::Params => "params",
            Command::Save => "save",
            Command::Target(_) => "target",
            Command::Planner(_) => "planner",
            Command::GalvoStatus => "galvo status",
            Command::Grbl(_) => "grbl",
            Command::Servo(_) => "servo",
            Command::Preset(_) => "preset",
        }
    }

    /// Whether the reply has data lines before its closer (the console
    /// gives earlier output time to reach the host before it sends these).
    pub fn replies_with_data(&self) -> bool {
        matches!(
            self,
            Command::Help
                | Command::Version
                | Command::Status
                | Command::Get(_)
                | Command::Params
                | Command::GalvoStatus
                | Command::Servo(_)
        )
    }
}

/// The command in command-line syntax (numbers in shortest form: no
/// `core` float formatting, see [`crate::text`]).
impl fmt::Debug for Command {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Command::Pattern { pattern, once } => {
                write!(f, "pattern {pattern}{}", if *once { " once" } else { "" })
            }
            Command::Goto(p) => write!(f, "goto {} {}", Shortest(p.x_cm), Shortest(p.y_cm)),
            Command::Grid { xi, yi } => write!(f, "grid {xi} {yi}"),
            Command::Laser(m) => write!(f, "laser {}", m.name()),
            Command::Target(a) => write!(f, "target {}", a.name()),
            Command::Planner(p) => write!(f, "planner {}", p.name()),
            Command::Model(AimModel::Exact) => f.write_str("model exact"),
            Command::Model(AimModel::Seed) => f.write_str("model seed"),
            Command::Set { param, value } => write!(f, "set {} {}", param.name, Shortest(*value)),
            Command::Get(param) => write!(f, "get {}", param.name),
            Command::Grbl(line) => f.write_str(line.as_str()),
            Command::Trace(on) => f.write_str(if *on { "trace on" } else { "trace off" }),
            Command::Servo(setup) => write!(f, "{setup}"),
            Command::Preset(preset) => write!(f, "{preset}"),
            other => f.write_str(other.name()),
        }
    }
}

impl PartialEq for Command {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (
                Command::Pattern {
                    pattern: a,
                    once: x,
                },
                Command::Pattern {
                    pattern: b,
                    once: y,
                },
            ) => a == b && x == y,
            (Command::Goto(a), Command::Goto(b)) => a == b,
            (Command::Grid { xi: a, yi: b }, Command::Grid { xi: c, yi: d }) => a == c && b == d,
            (Command::Laser(a), Command::Laser(b)) => a == b,
            (Command::Target(a), Command::Target(b)) => a == b,
            (Command::Planner(a), Command::Planner(b)) => a == b,
            (Command::Model(a), Command::Model(b)) => a == b,
            (Command::Set { param: a, value: x }, Command::Set { param: b, value: y }) => {
                a.name == b.name && x == y
            }
            (Command::Get(a), Command::Get(b)) => a.name == b.name,
            (Command::Grbl(a), Command::Grbl(b)) => a == b,
            (Command::Trace(a), Command::Trace(b)) => a == b,
            (Command::Servo(a), Command::Servo(b)) => a == b,
            (Command::Preset(a), Command::Preset(b)) => a == b,
            (a, b) => core::mem::discriminant(a) == core::mem::discriminant(b),
        }
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Command {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "{}", defmt::Debug2Format(self))
    }
}

/// Depth of the command queue. One command is in flight at a time (the
/// console waits for its closing reply to be queued), so a small queue
/// suffices.
pub const COMMAND_QUEUE_DEPTH: usize = 2;

/// Channels between the console task and the sequencer task.
pub struct CommandLink {
    /// Console → sequencer.
    pub commands: Channel<CriticalSectionRawMutex, Command, COMMAND_QUEUE_DEPTH>,
    /// Replies and notices → console: whole lines, queued without waiting
    /// (see [`Outbound`]).
    pub outbound: Outbound,
    /// Stop request from the board's button: stop and laser off, no reply.
    pub stop_request: Signal<CriticalSectionRawMutex, ()>,
    /// grbl realtime commands (`?`, `!`, `~`, 0x18, …) taken out of the
    /// console's byte stream, in arrival order; acted on at once, also
    /// while a line waits for room in the motion queue. When full (a host
    /// flooding `?`), further ones are dropped.
    pub realtime: Channel<CriticalSectionRawMutex, RealtimeRequest, REALTIME_QUEUE_DEPTH>,
    /// What the PELCO port has seen (`pelco status`, answered by the
    /// console itself).
    pub pelco: PelcoStatus,
    /// `trace on`: laser changes and laser-deciding events are reported as
    /// notices (`app::trace`).
    trace: AtomicBool,
}

/// A realtime command as the console took it out of the byte stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RealtimeRequest {
    /// The command.
    pub command: Realtime,
    /// Free bytes in the console's RX buffer when it arrived (grbl's
    /// `Bf:` second field).
    pub rx_free_bytes: u16,
}

/// Depth of the realtime command queue.
pub const REALTIME_QUEUE_DEPTH: usize = 8;

impl CommandLink {
    /// Empty channels (usable in a `static`).
    pub const fn new() -> Self {
        Self {
            commands: Channel::new(),
            outbound: Outbound::new(),
            stop_request: Signal::new(),
            realtime: Channel::new(),
            pelco: PelcoStatus::new(),
            trace: AtomicBool::new(false),
        }
    }

    /// Whether `trace on` is in force.
    pub fn tracing(&self) -> bool {
        self.trace.load(Ordering::Relaxed)
    }

    /// Turns the event trace on or off (`trace on|off`).
    pub fn set_tracing(&self, on: bool) {
        self.trace.store(on, Ordering::Relaxed);
    }

    /// Queues an unsolicited notice line, printed in brackets. Never
    /// waits: when the host is not reading and the queue is full it is
    /// dropped and counted, and the count is reported later.
    pub fn notify(&self, args: fmt::Arguments<'_>) {
        self.outbound.push_fmt(LineKind::Notice, args);
    }

    /// The replies to the command in flight (the sequencer's, whichever
    /// task sent the command).
    pub fn reply(&self) -> Reply<'_> {
        Reply::new(&self.outbound, Origin::Command)
    }

    /// Lines that are not the command in flight's: the console's own
    /// answers to lines it does not dispatch, realtime reports (see
    /// [`Origin::Direct`]).
    pub fn direct_reply(&self) -> Reply<'_> {
        Reply::new(&self.outbound, Origin::Direct)
    }

    /// Queues one data line of the current reply (see [`Reply::data`]).
    pub fn data(&self, args: fmt::Arguments<'_>) {
        self.reply().data(args);
    }

    /// Queues one data line already formatted (see [`Reply::data_line`]).
    pub fn data_line(&self, line: ReplyText) {
        self.reply().data_line(line);
    }

    /// Closes the current reply with `ok` (see [`Reply::ok`]).
    pub fn ok(&self) {
        self.reply().ok();
    }

    /// Closes the current reply with grbl's `error:N` (see
    /// [`Reply::grbl_error`]).
    pub fn grbl_error(&self, error: crate::grbl::GrblError) {
        self.reply().grbl_error(error);
    }

    /// Closes the current reply with `error: <reason>` (see
    /// [`Reply::error`]).
    pub fn error(&self, reason: impl fmt::Display) {
        self.reply().error(reason);
    }
}

impl Default for CommandLink {
    fn default() -> Self {
        Self::new()
    }
}
