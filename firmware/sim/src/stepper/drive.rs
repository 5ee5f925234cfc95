//! The simulated board's stepper outputs: every STEP/DIR/ENABLE edge goes
//! to the driver models ([`PanTiltDrivers`]) with its time, the step timer
//! is virtual time (1 µs ticks, deadlines that do not drift). The STEP
//! pulses are the reference board's: a one-pulse timer at [`TIMER_HZ`]
//! programmed by [`OnePulseTiming`], its edges where that timer puts them.

use std::cell::RefCell;
use std::rc::Rc;

use laser_app::stepper::{DriverSignals, OnePulseTiming, STEP_TIMER_HZ, StepPace, StepperDrive};

use super::pan_tilt::{PanTiltDrivers, StepEdge, StepPin, StepperGeometry};
use super::switch::LimitSwitch;

// The step timer's ticks are embassy-time's.
const _: () = assert!(STEP_TIMER_HZ as u64 == embassy_time::TICK_HZ);

/// Clock of the modelled pulse timer, Hz: the STM32 board's TIM1 (APB2
/// timers at 168 MHz).
pub const TIMER_HZ: u32 = 168_000_000;

/// The stepper outputs of the simulated board (implements
/// [`StepperDrive`]).
pub struct SimStepperDrive {
    drivers: Rc<RefCell<PanTiltDrivers>>,
    signals: DriverSignals,
    /// The pulse timer's values for `signals`.
    timing: OnePulseTiming,
    /// When the pulse timer stops after its last pulse, ns: an event
    /// before then waits for it, as the board's does.
    timer_busy_until_ns: u64,
    pace: StepPace,
    dir: [bool; 2],
    /// The true geometry (where the counted steps point).
    geometry: StepperGeometry,
    /// Each axis's limit switch, if it has one, and whether it is closed.
    switches: [Option<(LimitSwitch, bool)>; 2],
}

impl SimStepperDrive {
    /// Outputs into `drivers`; `switches` (`[pan, tilt]`) close at joint
    /// angles of the true `geometry`.
    pub fn new(
        drivers: Rc<RefCell<PanTiltDrivers>>,
        geometry: StepperGeometry,
        switches: [Option<LimitSwitch>; 2],
    ) -> Self {
        let signals = DriverSignals {
            pulse_ns: 0,
            dir_setup_ns: 0,
            enable_active_high: false,
        };
        Self {
            drivers,
            signals,
            timing: OnePulseTiming::new(TIMER_HZ, signals),
            timer_busy_until_ns: 0,
            pace: StepPace::new(),
            dir: [false; 2],
            geometry,
            switches: switches.map(|s| s.map(|s| (s, false))),
        }
    }
}

fn now_ns() -> u64 {
    crate::clock::now_us() * 1000
}

impl StepperDrive for SimStepperDrive {
    /// Records the logical state (the ENABLE pin's level follows the
    /// configured polarity).
    fn set_enabled(&mut self, enabled: bool) {
        crate::executor::simulator_work(|| {
            self.drivers.borrow_mut().enable.push((now_ns(), enabled));
        });
    }

    fn set_signals(&mut self, signals: DriverSignals) {
        self.signals = signals;
        self.timing = OnePulseTiming::new(TIMER_HZ, signals);
    }

    /// The edges go to the driver models as simulator work (not charged
    /// to the firmware task).
    fn step(&mut self, step: [bool; 2], negative: [bool; 2]) {
        crate::executor::simulator_work(|| self.record_step(step, negative));
    }

    async fn wait_ticks(&mut self, ticks: u32) {
        self.pace.wait_ticks(ticks).await;
    }

    fn restart(&mut self) {
        self.pace.restart();
    }

    /// The switches at the joint angles of the counted steps.
    fn limits(&mut self) -> [bool; 2] {
        let steps = self.drivers.borrow().counted_steps();
        let joints = self.geometry.joints(steps);
        let mut pressed = [false; 2];
        for (i, switch) in self.switches.iter_mut().enumerate() {
            let (Some((s, closed)), Some(j)) = (switch.as_mut(), joints) else {
                continue;
            };
            let angle = if i == 0 { j.yaw_deg } else { j.pitch_deg };
            *closed = s.closed_at(angle, *closed);
            pressed[i] = *closed;
        }
        pressed
    }
}

impl SimStepperDrive {
    fn record_step(&mut self, step: [bool; 2], negative: [bool; 2]) {
        let t = now_ns().max(self.timer_busy_until_ns);
        let mut drivers = self.drivers.borrow_mut();
        let mut dir_changed = false;
        for axis in 0..2u8 {
            let i = usize::from(axis);
            if negative[i] != self.dir[i] {
                self.dir[i] = negative[i];
                dir_changed = true;
                drivers.edge(StepEdge {
                    t_ns: t,
                    axis,
                    pin: StepPin::Dir,
                    high: negative[i],
                });
            }
        }
        let Some(pulse) = self.timing.event(step, dir_changed) else {
            return;
        };
        let rise = t + self.timing.counts_ns(pulse.rise_counts());
        let fall = t + self.timing.counts_ns(pulse.fall_counts());
        self.timer_busy_until_ns = fall;
        for axis in 0..2u8 {
            if !pulse.pulses(usize::from(axis)) {
                continue;
            }
            for (t_ns, high) in [(rise, true), (fall, false)] {
                drivers.edge(StepEdge {
                    t_ns,
                    axis,
                    pin: StepPin::Step,
                    high,
                });
            }
        }
    }
}
