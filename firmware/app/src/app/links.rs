//! [`Links`], the channels and shared state every task body is built with.

use crate::command::CommandLink;
use crate::galvo::GalvoLink;
use crate::laser_controls::ControlsLink;
use crate::laser_gate::LaserGate;
use crate::servo::task::ServoLink;
use crate::status::StatusBoard;
use crate::stepper::StepperLink;

/// The channels and shared state between the tasks. The board owns them
/// (`static`s on the target, leaked per run in the simulator) and lends
/// them for the program's life.
#[derive(Clone, Copy)]
pub struct Links {
    /// Console ↔ sequencer (commands, replies, stop requests).
    pub command: &'static CommandLink,
    /// Sequencer ↔ servo bus task.
    pub servo: &'static ServoLink,
    /// Sequencer ↔ galvo loop (no loop serves it on a board without a
    /// galvo DAC).
    pub galvo: &'static GalvoLink,
    /// What the firmware is doing (for the LEDs, the watchdog, the
    /// simulator).
    pub status: &'static StatusBoard,
    /// The master laser gate (its close hook is the board's).
    pub gate: &'static LaserGate,
    /// Sequencer ↔ stepper task ↔ step timer (no task serves it on a
    /// board without stepper outputs).
    pub stepper: &'static StepperLink,
    /// Laser-controls task ↔ sequencer (nothing publishes on it on a
    /// board without the controls).
    pub controls: &'static ControlsLink,
}
