//! Laser pointing controller firmware for the STM32F4DISCOVERY.
//!
//! `board::init` brings up clocks and peripherals (laser off first) and
//! starts the USB device stack; `laser_app::app::wire` then builds the
//! application's tasks from the board's parts — the same wiring the host
//! simulator runs: console → command channel → sequencer → servo bus
//! (USART2); the galvo loop on its own executor (an interrupt above
//! thread mode) feeding the DAC stream (`galvo_dac`); LEDs, stop button
//! and watchdog alongside.
#![no_std]
#![no_main]

mod board;
mod galvo_dac;
mod laser_gate;
mod laser_pwm;
mod panic;
mod parts;
mod rs485;
mod settings_flash;
mod tasks;

use defmt_rtt as _;
use embassy_executor::{InterruptExecutor, Spawner};
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::InterruptExt;
use laser_app::app::{Links, wire};
use laser_app::command::CommandLink;
use laser_app::galvo::GalvoLink;
use laser_app::servo::task::ServoLink;
use laser_app::status::StatusBoard;

/// Console ↔ sequencer channels.
static COMMAND_LINK: CommandLink = CommandLink::new();
/// Sequencer ↔ servo task channels.
static SERVO_LINK: ServoLink = ServoLink::new();
/// Sequencer ↔ galvo loop channels.
static GALVO_LINK: GalvoLink = GalvoLink::new();
/// Shared state for LEDs and the watchdog.
static STATUS: StatusBoard = StatusBoard::new();
/// Sequencer ↔ stepper task ↔ step timer.
static STEPPER_LINK: laser_app::stepper::StepperLink = laser_app::stepper::StepperLink::new();
/// Laser-controls task ↔ sequencer.
static CONTROLS_LINK: laser_app::laser_controls::ControlsLink =
    laser_app::laser_controls::ControlsLink::new();
/// Runs the galvo loop in the UART4 interrupt (UART4 itself is unused).
static GALVO_EXECUTOR: InterruptExecutor = InterruptExecutor::new();

#[interrupt]
unsafe fn UART4() {
    // SAFETY: the galvo executor's own interrupt, started below.
    unsafe { GALVO_EXECUTOR.on_interrupt() }
}

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let board = board::init(spawner);
    let links = Links {
        command: &COMMAND_LINK,
        servo: &SERVO_LINK,
        galvo: &GALVO_LINK,
        status: &STATUS,
        gate: &laser_gate::LASER_GATE,
        stepper: &STEPPER_LINK,
        controls: &CONTROLS_LINK,
    };
    interrupt::UART4.set_priority(board::GALVO_PRIORITY);
    let galvo = GALVO_EXECUTOR.start(interrupt::UART4);
    let mut spawners = tasks::TaskSpawner {
        thread: spawner,
        galvo,
    };
    wire(board, links, &mut spawners);
}
