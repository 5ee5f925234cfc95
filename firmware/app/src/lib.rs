#![no_std]
//! Firmware application logic of the laser pointing controller, independent
//! of the HAL so the host simulator runs exactly the code the target runs.
//!
//! Dataflow (one module per stage):
//! [`usb`] (command-line task body) → [`command`] (the command channel) →
//! [`sequencer`] (task body that runs commands and patterns).
//! Text handling lives in [`cli`].

pub mod build_info;
pub mod cli;
pub mod command;
mod log;
pub mod sequencer;
pub mod usb;
