//! The stepper pan/tilt's parameters ([`StepperConfig`], from the
//! settings), its driver signalling and homing, and the step timer's
//! fixed rates.

use kinematics_core::gimbal::{Gimbal, GimbalGeometry, GimbalModel, JointAngles};
use kinematics_core::servo::Direction;
use kinematics_core::stepper::StepperAxis;

use super::link::messages::StepperRefusal;
use crate::settings::StepperSettings;

/// Step-timer frequency, Hz (1 µs ticks: embassy-time's tick).
pub const STEP_TIMER_HZ: u32 = 1_000_000;
/// Length of a prepared segment, s (grbl's order of magnitude).
pub const SEGMENT_S: f64 = 0.0015;

/// How the driver inputs are signalled: STEP pulse width, DIR setup
/// time, ENABLE polarity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriverSignals {
    /// STEP high time, ns.
    pub pulse_ns: u32,
    /// DIR stable before the rising STEP edge, ns.
    pub dir_setup_ns: u32,
    /// ENABLE is active high (else active low, as on TB6600-class
    /// drivers' ENA− input).
    pub enable_active_high: bool,
}

/// Homing: which axes have switches, where they are, how fast to find
/// them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HomingConfig {
    /// Joint direction towards each axis's switch (+1/−1), 0: no switch,
    /// `[pan, tilt]`.
    pub dir: [i8; 2],
    /// Joint angle where each switch closes, degrees `[pan, tilt]`.
    pub switch_deg: [f64; 2],
    /// Seek and pull-off speed, °/s.
    pub seek_deg_s: f64,
    /// Latch (slow approach) speed, °/s.
    pub latch_deg_s: f64,
    /// Back-off and pull-off distance, degrees.
    pub pulloff_deg: f64,
}

/// The stepper pan/tilt's parameters (from the settings).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepperConfig {
    /// Motor full-step angle, degrees.
    pub full_step_deg: f64,
    /// Driver microsteps per full step.
    pub microsteps: u16,
    /// Step count sign vs joint angle, `[pan, tilt]`.
    pub direction: [Direction; 2],
    /// Joint angle at step position 0 (power-up), degrees `[pan, tilt]`.
    pub zero_deg: [f64; 2],
    /// Soft limits: lowest joint angle, degrees `[pan, tilt]`.
    pub min_deg: [f64; 2],
    /// Soft limits: highest joint angle, degrees `[pan, tilt]`.
    pub max_deg: [f64; 2],
    /// Highest joint speed of either axis, °/s.
    pub max_speed_deg_s: f64,
    /// Joint acceleration limit, °/s².
    pub accel_deg_s2: f64,
    /// grbl's junction deviation, degrees of joint travel.
    pub junction_deviation_deg: f64,
    /// STEP pulse width, DIR setup time, ENABLE polarity.
    pub signals: DriverSignals,
    /// Drivers released after this long at rest, ms (0: always held, the
    /// default: a released pan/tilt may sag off the point it holds).
    pub idle_release_ms: u32,
    /// Homing switches and speeds.
    pub homing: HomingConfig,
    /// The pointing geometry: the exact model with the pan/tilt's OL.
    pub gimbal: Gimbal,
}

impl Default for StepperConfig {
    /// The seed's pan/tilt ([`StepperSettings`]' defaults: 1.8° at 32
    /// microsteps, 0.05625° per step) with OL = 0 on the default board.
    fn default() -> Self {
        Self::from_settings(
            &StepperSettings::default(),
            Gimbal {
                model: GimbalModel::Exact,
                geometry: GimbalGeometry {
                    ol_cm: 0.0,
                    ..GimbalGeometry::default()
                },
            },
        )
    }
}

impl StepperConfig {
    /// The parameters `s` (checked by the settings) with the pointing
    /// geometry `gimbal`.
    pub fn from_settings(s: &StepperSettings, gimbal: Gimbal) -> Self {
        let direction = |sign: i8| Direction::from_sign(sign).unwrap_or_default();
        // Checked ranges: whole 1..=256 microsteps, pulse and setup ≤ 100 µs.
        let ns = |us: f64| libm::round(us * 1000.0) as u32;
        Self {
            full_step_deg: s.full_step_deg,
            microsteps: s.microsteps as u16,
            direction: [direction(s.pan.direction), direction(s.tilt.direction)],
            zero_deg: [s.pan.zero_deg, s.tilt.zero_deg],
            min_deg: [s.pan.min_deg, s.tilt.min_deg],
            max_deg: [s.pan.max_deg, s.tilt.max_deg],
            max_speed_deg_s: s.max_speed_deg_s,
            accel_deg_s2: s.accel_deg_s2,
            junction_deviation_deg: s.junction_deviation_deg,
            signals: DriverSignals {
                pulse_ns: ns(s.pulse_us),
                dir_setup_ns: ns(s.dir_setup_us),
                enable_active_high: s.enable_active_high == 1.0,
            },
            idle_release_ms: s.idle_release_ms as u32,
            homing: HomingConfig {
                // Whole −1..=1 (checked).
                dir: [s.pan.home_dir as i8, s.tilt.home_dir as i8],
                switch_deg: [s.pan.home_deg, s.tilt.home_deg],
                seek_deg_s: s.home_seek_deg_s,
                latch_deg_s: s.home_latch_deg_s,
                pulloff_deg: s.home_pulloff_deg,
            },
            gimbal,
        }
    }

    /// Degrees per microstep.
    pub fn deg_per_step(&self) -> f64 {
        self.full_step_deg / f64::from(self.microsteps.max(1))
    }

    /// The microstep mapping of axis `i` (0 pan, 1 tilt).
    pub fn axis(&self, i: usize) -> StepperAxis {
        StepperAxis {
            deg_per_step: self.deg_per_step(),
            direction: self.direction[i & 1],
        }
    }

    /// Joint angles of step positions `[pan, tilt]`, degrees.
    pub fn joints_of(&self, steps: [i32; 2]) -> Option<JointAngles> {
        let angle = |i: usize| self.axis(i).steps_to_angle(steps[i]).ok();
        Some(JointAngles {
            yaw_deg: self.zero_deg[0] + angle(0)?,
            pitch_deg: self.zero_deg[1] + angle(1)?,
        })
    }

    /// Nearest step positions for joint angles `j`, inside the soft
    /// limits.
    ///
    /// Errors: [`StepperRefusal::SoftLimit`], [`StepperRefusal::Unreachable`].
    pub fn steps_of(&self, j: JointAngles) -> Result<[i32; 2], StepperRefusal> {
        let joints = [j.yaw_deg, j.pitch_deg];
        let mut steps = [0; 2];
        for (i, (step, angle)) in steps.iter_mut().zip(joints).enumerate() {
            if !(self.min_deg[i]..=self.max_deg[i]).contains(&angle) {
                return Err(StepperRefusal::SoftLimit);
            }
            *step = self
                .axis(i)
                .angle_to_steps(angle - self.zero_deg[i])
                .map_err(|_| StepperRefusal::Unreachable)?;
        }
        Ok(steps)
    }
}
