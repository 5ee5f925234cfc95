//! Laser pointing controller firmware for the STM32F4DISCOVERY.
//!
//! `board::init` brings up clocks and peripherals (laser off first); the
//! tasks are wired as the dataflow goes: USB device + console → command
//! channel → sequencer → servo task (USART2); LEDs, stop button and
//! watchdog alongside.
#![no_std]
#![no_main]

mod board;
mod panic;
mod settings_flash;
mod tasks;

use defmt_rtt as _;
use embassy_executor::Spawner;
use laser_app::command::CommandLink;
use laser_app::servo::task::ServoLink;
use laser_app::status::StatusBoard;

/// Console ↔ sequencer channels.
static COMMAND_LINK: CommandLink = CommandLink::new();
/// Sequencer ↔ servo task channels.
static SERVO_LINK: ServoLink = ServoLink::new();
/// Shared state for LEDs and the watchdog.
static STATUS: StatusBoard = StatusBoard::new();

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let b = board::init();
    spawner.spawn(defmt::unwrap!(tasks::usb_device(b.usb_device)));
    spawner.spawn(defmt::unwrap!(tasks::usb_console(
        b.usb_tx,
        b.usb_rx,
        &COMMAND_LINK
    )));
    spawner.spawn(defmt::unwrap!(tasks::servo(
        b.servo_tx,
        b.servo_rx,
        &SERVO_LINK
    )));
    spawner.spawn(defmt::unwrap!(tasks::sequencer(
        &COMMAND_LINK,
        &SERVO_LINK,
        &STATUS,
        b.laser,
        b.settings,
    )));
    spawner.spawn(defmt::unwrap!(tasks::leds(
        b.heartbeat_led,
        b.laser_led,
        b.fault_led,
        &STATUS
    )));
    spawner.spawn(defmt::unwrap!(tasks::stop_button(b.button, &COMMAND_LINK)));
    spawner.spawn(defmt::unwrap!(tasks::watchdog(
        b.iwdg,
        &STATUS,
        &SERVO_LINK
    )));
}
