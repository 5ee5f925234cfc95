//! The STM32F4DISCOVERY's peripherals as the application's parts: each
//! implements one of `laser-app`'s board traits
//! ([`laser_app::app::Board`] and friends) over the HAL.

use embassy_stm32::Peri;
use embassy_stm32::exti::ExtiInput;
use embassy_stm32::gpio::{Input, Output};
use embassy_stm32::mode::Async;
use embassy_stm32::peripherals::{IWDG, USB_OTG_FS};
use embassy_stm32::usb::Driver;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_time::{Duration, Instant, Timer};
use embassy_usb::class::cdc_acm::{BufferedReceiver, Sender};
use laser_app::app::{Console, Indicators, Leds, StopButton, WATCHDOG_TIMEOUT_US, Watchdog};

/// The USB driver type of this board.
pub type UsbDriver = Driver<'static, USB_OTG_FS>;

/// The command line on the USB CDC-ACM port.
pub struct UsbConsole {
    /// CDC-ACM transmit half.
    pub tx: Sender<'static, UsbDriver>,
    /// CDC-ACM receive half (buffered).
    pub rx: BufferedReceiver<'static, UsbDriver>,
}

impl Console for UsbConsole {
    type Rx = BufferedReceiver<'static, UsbDriver>;
    type Tx = Sender<'static, UsbDriver>;

    async fn connected(&mut self) -> (&mut Self::Rx, &mut Self::Tx) {
        self.rx.wait_connection().await;
        (&mut self.rx, &mut self.tx)
    }
}

/// Status LEDs: heartbeat (green), laser (orange), fault (red).
pub struct StatusLeds {
    /// PD12.
    pub heartbeat: Output<'static>,
    /// PD13.
    pub laser: Output<'static>,
    /// PD14.
    pub fault: Output<'static>,
}

impl Indicators for StatusLeds {
    fn show(&mut self, leds: Leds) {
        self.laser.set_level(leds.laser.into());
        self.fault.set_level(leds.fault.into());
        self.heartbeat.set_level(leds.heartbeat.into());
    }
}

/// Debounce of the user button: edges this soon after a press are bounce.
const DEBOUNCE: Duration = Duration::from_millis(50);

/// The user button (PA0, rising edge on press), debounced.
pub struct UserButton {
    /// PA0 with its EXTI line.
    pub input: ExtiInput<'static, Async>,
    /// The next press counts from this time on.
    pub armed_from: Instant,
}

impl StopButton for UserButton {
    async fn pressed(&mut self) {
        Timer::at(self.armed_from).await;
        self.input.wait_for_rising_edge().await;
        self.armed_from = Instant::now() + DEBOUNCE;
    }
}

/// The independent watchdog (IWDG), [`WATCHDOG_TIMEOUT_US`].
pub struct IndependentDog {
    /// Created with the timeout; unleashed by [`Watchdog::start`].
    pub dog: IndependentWatchdog<'static, IWDG>,
}

impl IndependentDog {
    /// The IWDG with the application's timeout (not running yet).
    pub fn new(iwdg: Peri<'static, IWDG>) -> Self {
        Self {
            dog: IndependentWatchdog::new(iwdg, WATCHDOG_TIMEOUT_US),
        }
    }
}

impl Watchdog for IndependentDog {
    fn start(&mut self) {
        self.dog.unleash();
    }

    fn feed(&mut self) {
        self.dog.pet();
    }
}

/// The stepper pan/tilt's driver inputs: STEP and DIR per axis (PE9/PE10
/// pan, PE11/PE12 tilt) and the shared ENABLE (PE13); the limit switch
/// inputs (PE7 pan, PE8 tilt). Pulses are timed by
/// busy-waiting on the cycle counter's clock (2.5 µs STEP, 5 µs DIR setup
/// by default); the step schedule is embassy-time deadlines (1 µs ticks).
pub struct GpioStepper {
    /// STEP outputs, `[pan, tilt]`.
    pub step: [Output<'static>; 2],
    /// DIR outputs, `[pan, tilt]` (high = negative).
    pub dir: [Output<'static>; 2],
    /// The drivers' shared ENABLE.
    pub enable: Output<'static>,
    /// Limit switch inputs, `[pan, tilt]` (PE7, PE8): pulled up, a
    /// normally-open switch to ground closes (low = pressed; no switch
    /// reads open).
    pub limit: [Input<'static>; 2],
    /// Current pulse timing and ENABLE polarity.
    pub signals: laser_app::stepper::DriverSignals,
    /// The step timer's schedule.
    pub pace: laser_app::stepper::StepPace,
}

/// CPU cycles for `ns` nanoseconds at SYSCLK (rounded up).
fn cycles_for_ns(ns: u32) -> u32 {
    let per_us = crate::board::SYSCLK_HZ / 1_000_000;
    ns.div_ceil(1000).saturating_mul(per_us)
}

impl laser_app::stepper::StepperDrive for GpioStepper {
    fn set_enabled(&mut self, enabled: bool) {
        self.enable
            .set_level((enabled == self.signals.enable_active_high).into());
    }

    fn set_signals(&mut self, signals: laser_app::stepper::DriverSignals) {
        self.signals = signals;
    }

    fn step(&mut self, step: [bool; 2], negative: [bool; 2]) {
        let mut dir_changed = false;
        for (pin, negative) in self.dir.iter_mut().zip(negative) {
            if pin.is_set_high() != negative {
                pin.set_level(negative.into());
                dir_changed = true;
            }
        }
        if dir_changed {
            cortex_m::asm::delay(cycles_for_ns(self.signals.dir_setup_ns));
        }
        for (pin, _) in self.step.iter_mut().zip(step).filter(|(_, s)| *s) {
            pin.set_high();
        }
        cortex_m::asm::delay(cycles_for_ns(self.signals.pulse_ns));
        for pin in &mut self.step {
            pin.set_low();
        }
    }

    async fn wait_ticks(&mut self, ticks: u32) {
        self.pace.wait_ticks(ticks).await;
    }

    fn restart(&mut self) {
        self.pace.restart();
    }

    fn limits(&mut self) -> [bool; 2] {
        [self.limit[0].is_low(), self.limit[1].is_low()]
    }
}
