#![no_std]
//! Firmware application logic of the laser pointing controller, independent
//! of the HAL so the host simulator runs exactly the code the target runs.
//!
//! Dataflow (one module per stage):
//! [`usb`] (command-line task body) → [`command`] (the command channel) →
//! [`sequencer`] (task body that runs commands and patterns) →
//! [`servo`] (servo task body, speaking the `fashionstar` codec) and
//! [`galvo`] (the galvo loop body feeding the DAC).
//! The vocabulary below them all but number formatting ([`text`]) —
//! board points, cm ↔ mm, patterns and path figures, actuators, targets,
//! the aiming chain and the checks — is [`domain`].
//! Text handling lives in [`cli`] (number formatting, the bottom layer, in
//! [`text`]), parameters in [`settings`], shared
//! state for LEDs/watchdog/simulator in [`status`], the master laser gate
//! that no laser command or sample stream can override in [`laser_gate`].
//! The grbl 1.1 G-code protocol (realtime bytes, G-code parser, replies),
//! is [`grbl`]; the sequencer runs its G-code session and motion queue.
//! On top, [`app`] says what a board provides and wires every task once,
//! for the target and the simulator alike.

pub mod app;
pub mod build_info;
pub mod cli;
pub mod command;
pub mod domain;
pub mod galvo;
pub mod grbl;
pub mod laser_gate;
mod log;
pub mod outbound;
pub mod pelco;
pub mod sequencer;
pub mod servo;
pub mod settings;
pub mod status;
pub mod stepper;
pub mod text;
pub mod usb;
