//! The laser pointing controller's firmware on QEMU's `mps2-an386`
//! (Cortex-M4F): a third board beside the STM32F4DISCOVERY and the host
//! simulator, wired by the same `laser_app::app::wire`. Run it with
//! `cargo xtask qemu`; see `board.rs` for the peripherals.
#![no_std]
#![no_main]

mod board;
#[cfg(feature = "laser-controls")]
mod controls;
#[cfg(feature = "defmt-log")]
mod defmt_channel;
mod executor;
mod faults;
#[cfg(feature = "galvo-dac")]
mod galvo_dac;
mod interrupts;
mod log_channel;
mod mmio;
mod parts;
mod settings_ram;
mod stats;
mod tasks;
mod time_driver;
mod uart;
mod vectors;

use laser_app::app::{Links, wire};
use laser_app::command::CommandLink;
use laser_app::galvo::GalvoLink;
use laser_app::servo::task::ServoLink;
use laser_app::status::StatusBoard;

/// Console ↔ sequencer channels.
static COMMAND_LINK: CommandLink = CommandLink::new();
/// Sequencer ↔ servo task channels.
static SERVO_LINK: ServoLink = ServoLink::new();
/// Sequencer ↔ galvo loop channels (no loop serves them on this board).
static GALVO_LINK: GalvoLink = GalvoLink::new();
/// Sequencer ↔ stepper channels (no stepper task serves them on this board:
/// `target stepper` is refused).
static STEPPER_LINK: laser_app::stepper::StepperLink = laser_app::stepper::StepperLink::new();
/// Laser-controls task ↔ sequencer (nothing behind it without the
/// `laser-controls` feature).
static CONTROLS_LINK: laser_app::laser_controls::ControlsLink =
    laser_app::laser_controls::ControlsLink::new();
/// Shared state for LEDs and the watchdog.
static STATUS: StatusBoard = StatusBoard::new();

#[cortex_m_rt::entry]
fn main() -> ! {
    // The laser pin is low from reset (a static); the log channel first so
    // everything after can report.
    stats::paint_stack();
    uart::Uart::start(&uart::UART2);
    log_channel::init();
    #[cfg(feature = "defmt-log")]
    defmt_channel::init();
    time_driver::init();
    log::info!(
        "{} {} (git {}) booting on QEMU mps2-an386",
        laser_app::build_info::PRODUCT,
        laser_app::build_info::VERSION,
        laser_app::build_info::GIT_REV
    );
    let board = board::init();
    let links = Links {
        command: &COMMAND_LINK,
        servo: &SERVO_LINK,
        galvo: &GALVO_LINK,
        stepper: &STEPPER_LINK,
        status: &STATUS,
        gate: &parts::LASER_GATE,
        controls: &CONTROLS_LINK,
    };
    executor::run(|spawner| wire(board, links, &mut tasks::TaskSpawner(spawner)))
}
