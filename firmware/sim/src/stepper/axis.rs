//! One axis' driver and motor: the pulse-timing check and the rotor's
//! pull-out model ([`super`] describes both).

/// Timing a driver needs on its inputs, ns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriverTiming {
    /// Shortest STEP high and low time, ns.
    pub min_pulse_ns: u64,
    /// Shortest time DIR must be stable before a rising STEP edge, ns.
    pub dir_setup_ns: u64,
}

impl Default for DriverTiming {
    /// A TB6600-class driver: 2.5 µs pulses, 5 µs DIR setup.
    fn default() -> Self {
        Self {
            min_pulse_ns: 2_500,
            dir_setup_ns: 5_000,
        }
    }
}

/// What the motor can do with its load, in microsteps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorLimits {
    /// Microsteps per full step (the torque peaks at one full step of lag).
    pub microsteps: u32,
    /// Rate at which the torque has fallen to zero, microsteps/s.
    pub max_rate_steps_per_s: f64,
    /// Acceleration the peak torque gives the load at rest, microsteps/s².
    pub max_accel_steps_per_s2: f64,
}

impl Default for MotorLimits {
    /// A 1.8° NEMA-17 at 32 microsteps with a light laser head: torque gone
    /// at 64 000 microsteps/s (10 rev/s), 600 000 microsteps/s² (≈ 94
    /// rev/s²) at rest.
    fn default() -> Self {
        Self {
            microsteps: 32,
            max_rate_steps_per_s: 64_000.0,
            max_accel_steps_per_s2: 600_000.0,
        }
    }
}

/// Longest integration step of the rotor, s.
const ROTOR_DT_S: f64 = 5e-6;
/// Damping ratio at the small-signal resonance.
const DAMPING_RATIO: f64 = 0.4;

/// Pulse-timing violations of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TimingViolations {
    /// STEP high shorter than the minimum.
    pub short_high: u32,
    /// STEP low (between pulses) shorter than the minimum.
    pub short_low: u32,
    /// Rising STEP edge too soon after a DIR change.
    pub dir_setup: u32,
    /// DIR changed while STEP was high.
    pub dir_while_high: u32,
}

impl TimingViolations {
    /// Total violations.
    pub fn total(&self) -> u32 {
        self.short_high + self.short_low + self.dir_setup + self.dir_while_high
    }
}

/// A stall: when and where the rotor lost the step train.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stall {
    /// Time of the step that stalled the motor, ns.
    pub at_ns: u64,
    /// Commanded position then, microsteps.
    pub commanded_steps: i64,
    /// Rotor position minus commanded position then, microsteps.
    pub lag_steps: f64,
    /// Commanded rate then, microsteps/s.
    pub commanded_rate_steps_per_s: f64,
}

/// One axis: a driver and its motor.
#[derive(Debug, Clone)]
pub struct AxisDriver {
    timing: DriverTiming,
    limits: MotorLimits,
    step_high: bool,
    dir_negative: bool,
    dir_changed_ns: Option<u64>,
    step_changed_ns: Option<u64>,
    last_rise_ns: Option<u64>,
    /// Interval before the last rising edge, ns.
    last_interval_ns: Option<u64>,
    /// Steps counted by DIR, microsteps.
    counted: i64,
    /// Rotor position and rate, microsteps and microsteps/s, at `rotor_ns`.
    rotor: f64,
    rotor_rate: f64,
    rotor_ns: u64,
    /// Commanded rate over the last step interval, microsteps/s.
    commanded_rate: f64,
    /// The electrical period the rotor is locked to: 0 until it slips
    /// poles, then ± 4 full steps per slip, microsteps.
    slip_offset: f64,
    violations: TimingViolations,
    stalls: Vec<Stall>,
    /// Highest commanded rate seen, microsteps/s.
    peak_rate: f64,
    /// Largest |lag| while locked, microsteps.
    peak_lag: f64,
}

impl AxisDriver {
    /// A driver at rest at position 0, STEP low, DIR low (positive).
    pub fn new(timing: DriverTiming, limits: MotorLimits) -> Self {
        Self {
            timing,
            limits,
            step_high: false,
            dir_negative: false,
            dir_changed_ns: None,
            step_changed_ns: None,
            last_rise_ns: None,
            last_interval_ns: None,
            counted: 0,
            rotor: 0.0,
            rotor_rate: 0.0,
            rotor_ns: 0,
            commanded_rate: 0.0,
            slip_offset: 0.0,
            violations: TimingViolations::default(),
            stalls: Vec::new(),
            peak_rate: 0.0,
            peak_lag: 0.0,
        }
    }

    /// Steps counted from the STEP edges by DIR, microsteps.
    pub fn counted_steps(&self) -> i64 {
        self.counted
    }

    /// Where the rotor is, nearest microstep.
    pub fn rotor_steps(&self) -> i64 {
        self.rotor.round() as i64
    }

    /// Counted minus rotor position: the steps the motor lost.
    pub fn lost_steps(&self) -> i64 {
        self.counted - self.rotor_steps()
    }

    /// Pulse-timing violations so far.
    pub fn violations(&self) -> TimingViolations {
        self.violations
    }

    /// Every pole slip so far (each loses 4 full steps).
    pub fn stalls(&self) -> &[Stall] {
        &self.stalls
    }

    /// Highest commanded step rate seen, microsteps/s.
    pub fn peak_rate_steps_per_s(&self) -> f64 {
        self.peak_rate
    }

    /// Largest rotor lag while it followed, microsteps.
    pub fn peak_lag_steps(&self) -> f64 {
        self.peak_lag
    }

    /// The DIR input changes to `negative` at `t_ns`.
    pub fn set_dir(&mut self, negative: bool, t_ns: u64) {
        if negative == self.dir_negative {
            return;
        }
        if self.step_high {
            self.violations.dir_while_high += 1;
        }
        self.dir_negative = negative;
        self.dir_changed_ns = Some(t_ns);
    }

    /// The STEP input changes to `high` at `t_ns`.
    pub fn set_step(&mut self, high: bool, t_ns: u64) {
        if high == self.step_high {
            return;
        }
        let held_ns = self.step_changed_ns.map(|t| t_ns.saturating_sub(t));
        if held_ns.is_some_and(|held| held < self.timing.min_pulse_ns) {
            if high {
                self.violations.short_low += 1;
            } else {
                self.violations.short_high += 1;
            }
        }
        self.step_high = high;
        self.step_changed_ns = Some(t_ns);
        if high {
            self.rising_edge(t_ns);
        }
    }

    fn rising_edge(&mut self, t_ns: u64) {
        if self
            .dir_changed_ns
            .is_some_and(|t| t_ns.saturating_sub(t) < self.timing.dir_setup_ns)
        {
            self.violations.dir_setup += 1;
        }
        self.advance(t_ns);
        let sign = if self.dir_negative { -1.0 } else { 1.0 };
        let gap_ns = self.last_rise_ns.map(|t| t_ns.saturating_sub(t));
        self.commanded_rate = match gap_ns {
            Some(gap) if gap > 0 => sign * 1e9 / gap as f64,
            _ => 0.0,
        };
        self.last_interval_ns = gap_ns;
        self.last_rise_ns = Some(t_ns);
        self.counted += sign as i64;
        self.peak_rate = self.peak_rate.max(self.commanded_rate.abs());
    }

    /// The commanded rate at `t_ns`: the last interval's, until the train
    /// has paused for twice that interval (then at rest).
    fn commanded_rate_at(&self, t_ns: u64) -> f64 {
        match (self.last_rise_ns, self.last_interval_ns) {
            (Some(rise), Some(interval)) if t_ns.saturating_sub(rise) <= 2 * interval => {
                self.commanded_rate
            }
            _ => 0.0,
        }
    }

    /// Integrates the rotor up to `t_ns` (see the module doc).
    fn advance(&mut self, t_ns: u64) {
        let full_step = f64::from(self.limits.microsteps);
        let a_max = self.limits.max_accel_steps_per_s2;
        let omega = (a_max * core::f64::consts::FRAC_PI_2 / full_step).sqrt();
        let damping = 2.0 * DAMPING_RATIO * omega;
        let target = self.counted as f64;
        while self.rotor_ns < t_ns {
            let v_cmd = self.commanded_rate_at(self.rotor_ns);
            // At rest in its detent with nothing commanded: nothing moves.
            let at_rest = (self.rotor - self.slip_offset - target).abs() < 1e-6;
            if v_cmd == 0.0 && self.rotor_rate.abs() < 1e-6 && at_rest {
                self.rotor_ns = t_ns;
                break;
            }
            let h_ns = (t_ns - self.rotor_ns).min((ROTOR_DT_S * 1e9) as u64);
            let h = h_ns as f64 * 1e-9;
            let lag = self.rotor - target;
            let derate = (1.0 - self.rotor_rate.abs() / self.limits.max_rate_steps_per_s).max(0.0);
            // Holding torque plus damping, both from the phase currents:
            // together never more than the (speed-derated) peak torque.
            let pull = -a_max * (core::f64::consts::FRAC_PI_2 * lag / full_step).sin();
            let drive = pull + damping * (v_cmd - self.rotor_rate);
            // Back-EMF limits driving with the motion, not braking.
            let limit = if drive * self.rotor_rate > 0.0 {
                a_max * derate
            } else {
                a_max
            };
            let accel = drive.clamp(-limit, limit);
            self.rotor_rate += accel * h;
            self.rotor += self.rotor_rate * h;
            self.rotor_ns += h_ns;
            self.check_slip(target);
        }
    }

    /// Records a pole slip when the lag from the locked electrical period
    /// passes two and a half full steps (the rotor is then falling to the
    /// next stable point).
    fn check_slip(&mut self, target: f64) {
        let full_step = f64::from(self.limits.microsteps);
        let lag = self.rotor - target;
        let rel = lag - self.slip_offset;
        // Past the unstable point at two full steps, with a quarter of the
        // electrical period's hysteresis against wobbling around it.
        if rel.abs() <= 2.5 * full_step {
            if self.slip_offset == 0.0 {
                self.peak_lag = self.peak_lag.max(lag.abs());
            }
            return;
        }
        self.slip_offset += 4.0 * full_step * rel.signum();
        self.stalls.push(Stall {
            at_ns: self.rotor_ns,
            commanded_steps: self.counted,
            lag_steps: lag,
            commanded_rate_steps_per_s: self.commanded_rate_at(self.rotor_ns),
        });
    }

    /// Lets the rotor run on to `t_ns` with no further edges (it settles
    /// within a few ms; an abrupt halt from speed may slip poles here).
    pub fn settle(&mut self, t_ns: u64) {
        self.advance(t_ns);
    }
}
