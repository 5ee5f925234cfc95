//! Thin `#[embassy_executor::task]` wrappers: each hands board resources to
//! a task body from `laser-app` (or, for the USB device, LEDs, button and
//! watchdog, drives the HAL directly).

use core::sync::atomic::Ordering;

use embassy_stm32::Peri;
use embassy_stm32::exti::ExtiInput;
use embassy_stm32::gpio::Output;
use embassy_stm32::mode::Async;
use embassy_stm32::peripherals::{IWDG, USB_OTG_FS};
use embassy_stm32::usart::{RingBufferedUartRx, UartTx};
use embassy_stm32::usb::Driver;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_time::Timer;
use embassy_usb::UsbDevice;
use embassy_usb::class::cdc_acm::{BufferedReceiver, Sender};
use laser_app::command::CommandLink;
use laser_app::galvo::GalvoLink;
use laser_app::laser_gate::LaserGate;
use laser_app::sequencer::{LaserSwitch, Sequencer};
use laser_app::servo::task::{ServoBus, ServoBusConfig, ServoLink};
use laser_app::status::StatusBoard;

use crate::settings_flash::FlashSettings;

/// The USB driver type of this board.
pub type UsbDriver = Driver<'static, USB_OTG_FS>;

/// Runs the USB device stack (enumeration, control requests).
#[embassy_executor::task]
pub async fn usb_device(mut device: UsbDevice<'static, UsbDriver>) -> ! {
    device.run().await
}

/// Serves the command line on the CDC-ACM port; restarts on reconnect.
#[embassy_executor::task]
pub async fn usb_console(
    mut tx: Sender<'static, UsbDriver>,
    mut rx: BufferedReceiver<'static, UsbDriver>,
    link: &'static CommandLink,
) -> ! {
    loop {
        rx.wait_connection().await;
        defmt::info!("usb: host connected");
        let end = laser_app::usb::run_console(&mut rx, &mut tx, link).await;
        defmt::info!("usb: console ended ({})", end);
    }
}

/// Owns the servo UART (USART2, DMA both ways).
#[embassy_executor::task]
pub async fn servo(
    tx: UartTx<'static, Async>,
    rx: RingBufferedUartRx<'static>,
    link: &'static ServoLink,
) -> ! {
    ServoBus::new(rx, tx, ServoBusConfig::default())
        .run(link)
        .await
}

/// The laser-enable GPIO (active high), ANDed with the master laser gate:
/// it goes high only while the gate is open, and the gate's close hook
/// ([`crate::board::laser_gate_changed`]) pulls it low at once from
/// whatever context closed it.
pub struct LaserPin {
    /// PB0.
    pub pin: Output<'static>,
    /// The master gate.
    pub gate: &'static LaserGate,
}

impl LaserSwitch for LaserPin {
    fn set(&mut self, on: bool) {
        if on && self.gate.is_open() {
            self.pin.set_high();
            // A close between the check and the write has already run
            // its hook: look again so the pin cannot stay high.
            if !self.gate.is_open() {
                self.pin.set_low();
            }
        } else {
            self.pin.set_low();
        }
    }
}

/// Runs the sequencer (commands, patterns, laser).
#[embassy_executor::task]
pub async fn sequencer(
    link: &'static CommandLink,
    servo: &'static ServoLink,
    status: &'static StatusBoard,
    laser: LaserPin,
    store: FlashSettings,
) -> ! {
    let gate = laser.gate;
    // No galvo loop serves this link yet (no DAC output wired, see README,
    // Status): `target galvo|both` is refused.
    static GALVO: GalvoLink = GalvoLink::new();
    let mut sequencer = Sequencer::new(link, servo, &GALVO, status, laser, gate, store).await;
    sequencer.run().await
}

/// Status LEDs: heartbeat (green), laser (orange), fault (red).
#[embassy_executor::task]
pub async fn leds(
    mut heartbeat: Output<'static>,
    mut laser: Output<'static>,
    mut fault: Output<'static>,
    status: &'static StatusBoard,
) -> ! {
    let mut tick: u32 = 0;
    loop {
        let s = status.snapshot();
        laser.set_level((s.laser_on).into());
        fault.set_level((s.faulty_servo.is_some()).into());
        heartbeat.set_level(tick.is_multiple_of(10).into());
        tick = tick.wrapping_add(1);
        Timer::after_millis(100).await;
    }
}

/// User button PA0: stop the pattern and turn the laser off.
#[embassy_executor::task]
pub async fn stop_button(mut button: ExtiInput<'static, Async>, link: &'static CommandLink) -> ! {
    loop {
        button.wait_for_rising_edge().await;
        defmt::info!("button: stop");
        link.stop_request.signal(());
        // Debounce.
        Timer::after_millis(50).await;
    }
}

/// Independent watchdog, 4 s (a flash-sector erase for `save` stalls the
/// CPU for up to ~2 s): fed only while the sequencer and the servo task
/// both show progress, so a hung task resets the MCU (laser off at reset).
#[embassy_executor::task]
pub async fn watchdog(
    iwdg: Peri<'static, IWDG>,
    status: &'static StatusBoard,
    servo: &'static ServoLink,
) -> ! {
    let mut dog = IndependentWatchdog::new(iwdg, 4_000_000);
    dog.unleash();
    let mut last = (
        status.snapshot().heartbeat,
        servo.alive.load(Ordering::Relaxed),
    );
    loop {
        Timer::after_millis(1000).await;
        let now = (
            status.snapshot().heartbeat,
            servo.alive.load(Ordering::Relaxed),
        );
        if now.0 != last.0 && now.1 != last.1 {
            dog.pet();
        } else {
            defmt::warn!("watchdog: a task shows no progress; not feeding");
        }
        last = now;
    }
}
