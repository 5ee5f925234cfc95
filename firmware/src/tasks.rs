//! Thin `#[embassy_executor::task]` wrappers: each hands board resources to
//! a task body from `laser-app` (or, for the USB device and the LED, to the
//! HAL directly).

use embassy_stm32::gpio::Output;
use embassy_stm32::peripherals::USB_OTG_FS;
use embassy_stm32::usb::Driver;
use embassy_time::Timer;
use embassy_usb::UsbDevice;
use embassy_usb::class::cdc_acm::{BufferedReceiver, Sender};
use laser_app::command::CommandLink;

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

/// Runs the sequencer (commands, patterns).
#[embassy_executor::task]
pub async fn sequencer(link: &'static CommandLink) -> ! {
    laser_app::sequencer::run_sequencer(link).await
}

/// Blinks the heartbeat LED at 1 Hz (short flash) while the executor runs.
#[embassy_executor::task]
pub async fn heartbeat(mut led: Output<'static>) -> ! {
    loop {
        led.set_high();
        Timer::after_millis(100).await;
        led.set_low();
        Timer::after_millis(900).await;
    }
}
