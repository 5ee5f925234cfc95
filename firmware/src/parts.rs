//! The STM32F4DISCOVERY's peripherals as the application's parts: each
//! implements one of `laser-app`'s board traits
//! ([`laser_app::app::Board`] and friends) over the HAL.

use core::sync::atomic::{AtomicBool, Ordering};
use embassy_futures::select::{Either, select};
use embassy_stm32::Peri;
use embassy_stm32::exti::ExtiInput;
use embassy_stm32::gpio::OutputType;
use embassy_stm32::gpio::{Input, Output};
use embassy_stm32::mode::Async;
use embassy_stm32::pac;
use embassy_stm32::pac::timer::regs::CcmrOutputGp16;
use embassy_stm32::peripherals::{IWDG, PE9, PE11, TIM1, USB_OTG_FS};
use embassy_stm32::timer::low_level::Timer as HalTimer;
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::timer::{Ch1, Ch2};
use embassy_stm32::usb::Driver;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_time::{Duration, Instant, Timer};
use embassy_usb::class::cdc_acm::{BufferedReceiver, ControlChanged, Sender};
use embedded_io_async::Read;
use laser_app::app::{
    Console, HostPresence, Indicators, Leds, StopButton, WATCHDOG_TIMEOUT_US, Watchdog,
};
use laser_app::stepper::{
    CCMR1_IDLE, DriverSignals, OnePulseTiming, StepPace, StepperConfig, StepperDrive,
};

/// The USB driver type of this board.
pub type UsbDriver = Driver<'static, USB_OTG_FS>;

/// The command line on the USB CDC-ACM port.
pub struct UsbConsole {
    /// CDC-ACM transmit half.
    pub tx: Sender<'static, UsbDriver>,
    /// CDC-ACM receive half (buffered).
    pub rx: BufferedReceiver<'static, UsbDriver>,
    /// The host's DTR (raised when a program opens the port).
    pub dtr: &'static UsbDtr,
}

impl Console for UsbConsole {
    type Rx = BufferedReceiver<'static, UsbDriver>;
    type Tx = Sender<'static, UsbDriver>;
    type Presence = &'static UsbDtr;

    /// Once the host dropped DTR (closed the port), what it had sent and
    /// the device not yet read is of that session: dropped until DTR rises
    /// again. A host that never raises DTR is served as it talks.
    async fn connected(&mut self) -> (&mut Self::Rx, &mut Self::Tx) {
        let mut stale = [0u8; 64];
        loop {
            self.rx.wait_connection().await;
            if self.dtr.control.dtr() {
                self.dtr.seen.store(true, Ordering::Relaxed);
                break;
            }
            if !self.dtr.seen.load(Ordering::Relaxed) {
                break;
            }
            let changed = self.dtr.control.control_changed();
            if let Either::Second(Err(_)) = select(changed, self.rx.read(&mut stale)).await {
                // Unplugged: the next host may not use DTR.
                self.dtr.seen.store(false, Ordering::Relaxed);
            }
        }
        (&mut self.rx, &mut self.tx)
    }

    fn presence(&self) -> &'static UsbDtr {
        self.dtr
    }
}

/// The CDC-ACM control lines: the host's DTR tells it has the port open.
pub struct UsbDtr {
    /// DTR/RTS changes (one waiter: the console task).
    pub control: ControlChanged<'static>,
    /// The host raised DTR since it was plugged in: it uses DTR, so DTR
    /// dropping is its hang-up.
    pub seen: AtomicBool,
}

impl HostPresence for &'static UsbDtr {
    async fn hung_up(&mut self) {
        loop {
            if self.control.dtr() {
                self.seen.store(true, Ordering::Relaxed);
            } else if self.seen.load(Ordering::Relaxed) {
                return;
            }
            self.control.control_changed().await;
        }
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

/// The stepper pan/tilt's driver inputs: STEP per axis from TIM1 in
/// one-pulse mode (PE9 = TIM1_CH1 pan, PE11 = TIM1_CH2 tilt, AF1), DIR per
/// axis (PE10 pan, PE12 tilt) and the shared ENABLE (PE13) as GPIO
/// outputs; the limit switch inputs (PE7 pan, PE8 tilt). A step event sets
/// DIR, writes the event's compare/reload/mode values
/// ([`OnePulseTiming::event`]) and starts the timer: it returns at once
/// and the hardware makes one pulse of the configured width per stepping
/// axis, the DIR setup time later when a DIR pin changed. The timer stops
/// itself at the pulse's end with both STEP pins low, so a halt, stop or
/// fault (nothing starts it again) leaves them low within one pulse. The
/// step schedule is embassy-time deadlines (1 µs ticks).
pub struct TimerStepper {
    /// TIM1 (its clock stays on while this lives).
    timer: HalTimer<'static, TIM1>,
    /// Pan STEP, PE9 in AF1 (TIM1_CH1).
    _pan_step: PwmPin<'static, TIM1, Ch1>,
    /// Tilt STEP, PE11 in AF1 (TIM1_CH2).
    _tilt_step: PwmPin<'static, TIM1, Ch2>,
    /// DIR outputs, `[pan, tilt]` (high = negative).
    dir: [Output<'static>; 2],
    /// The drivers' shared ENABLE.
    enable: Output<'static>,
    /// Limit switch inputs, `[pan, tilt]` (PE7, PE8): pulled up, a
    /// normally-open switch to ground closes (low = pressed; no switch
    /// reads open).
    limit: [Input<'static>; 2],
    /// Current pulse timing and ENABLE polarity.
    signals: DriverSignals,
    /// The timer values for those signals.
    timing: OnePulseTiming,
    /// The step timer's schedule.
    pace: StepPace,
}

impl TimerStepper {
    /// TIM1 set up for one-pulse STEP pulses (both channels forced
    /// inactive, outputs enabled, MOE), then the STEP pins switched to it
    /// (low until then); `dir` and `enable` created at their idle levels.
    pub fn new(
        tim1: Peri<'static, TIM1>,
        step: (Peri<'static, PE9>, Peri<'static, PE11>),
        dir: [Output<'static>; 2],
        enable: Output<'static>,
        limit: [Input<'static>; 2],
    ) -> Self {
        let timer = HalTimer::new(tim1);
        let tim = pac::TIM1;
        tim.ccmr_output(0).write_value(CcmrOutputGp16(CCMR1_IDLE));
        tim.ccer().write(|w| {
            w.set_cce(0, true);
            w.set_cce(1, true);
        });
        tim.bdtr().write(|w| w.set_moe(true));
        let signals = StepperConfig::default().signals;
        let mut stepper = Self {
            timing: OnePulseTiming::new(timer.get_clock_frequency().0, signals),
            timer,
            _pan_step: PwmPin::new(step.0, OutputType::PushPull),
            _tilt_step: PwmPin::new(step.1, OutputType::PushPull),
            dir,
            enable,
            limit,
            signals,
            pace: StepPace::new(),
        };
        stepper.set_signals(signals);
        stepper
    }

    /// Waits for a pulse still in flight to end (the timer clears CEN at
    /// its update): an event that comes early, after a late one, must not
    /// change DIR under a high STEP or restart a running pulse. At most
    /// the DIR setup plus the pulse (≤ 200 µs); none at the scheduled rate
    /// (the settings keep both within one step period).
    fn wait_idle(&self) {
        while pac::TIM1.cr1().read().cen() {}
    }
}

impl StepperDrive for TimerStepper {
    fn set_enabled(&mut self, enabled: bool) {
        self.enable
            .set_level((enabled == self.signals.enable_active_high).into());
    }

    /// The counts for `signals` (the only division of the step path's
    /// arithmetic, here at rest), the prescaler loaded at once by an
    /// update event with the counter stopped.
    fn set_signals(&mut self, signals: DriverSignals) {
        self.wait_idle();
        self.signals = signals;
        self.timing = OnePulseTiming::new(self.timer.get_clock_frequency().0, signals);
        pac::TIM1.psc().write_value(self.timing.prescaler());
        self.timer.generate_update_event();
    }

    fn step(&mut self, step: [bool; 2], negative: [bool; 2]) {
        self.wait_idle();
        let mut dir_changed = false;
        for (pin, negative) in self.dir.iter_mut().zip(negative) {
            if pin.is_set_high() != negative {
                pin.set_level(negative.into());
                dir_changed = true;
            }
        }
        let Some(pulse) = self.timing.event(step, dir_changed) else {
            return;
        };
        let tim = pac::TIM1;
        tim.ccmr_output(0).write_value(CcmrOutputGp16(pulse.ccmr1));
        for channel in 0..2 {
            tim.ccr(channel).write(|w| w.set_ccr(pulse.compare));
        }
        tim.arr().write(|w| w.set_arr(pulse.reload));
        // Up-counting, no preload: one pulse, then the timer stops itself.
        tim.cr1().write(|w| {
            w.set_opm(true);
            w.set_cen(true);
        });
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
