//! The stepper pan/tilt's parameters (ids 160–183, one run of the saved
//! record): microstep mapping, per-axis direction, zero and soft limits,
//! motion limits, the driver's signal timing and homing.
//!
//! # Record size (the decision)
//!
//! They are stored like every other parameter: f64 values in the id-keyed
//! version-3 record, so nothing about the framing changes and a record
//! saved before they existed (488 bytes) loads as it is, the 24 values at
//! their defaults (`defaulted = 24`; the next `save` writes them). The
//! record grows by one run head and 24 values to 684 bytes. A 128 KiB
//! sector then holds ≈ 190 saves before an erase instead of ≈ 260
//! (100 000 erase cycles × 2 sectors × 190 saves is still 38 million
//! saves); packing them into f32 or a second map item would save ~100
//! bytes for a new framing version and its migration, not worth it. The
//! power-cut tests scale the sectors to 2 KiB (1/64) so a sector still
//! holds two records and the hand-over is cut too.

use super::error::SettingsError;
use kinematics_core::stepper::motion::{
    MAX_ACCEL_STEPS_PER_S2, MIN_ACCEL_STEPS_PER_S2, MIN_RATE_STEPS_PER_S,
};
use kinematics_core::stepper::{SEED_FULL_STEP_DEG, SEED_MICROSTEPS};

/// Highest step rate of either axis, steps/s (the step timer's 1 µs tick
/// leaves 20 ticks per step; the M4 budget of issue 13).
pub const MAX_STEP_RATE_STEPS_S: f64 = 50_000.0;

/// One stepper axis: direction, zero and soft limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepperAxisSettings {
    /// +1 or −1: step count sign relative to the joint angle.
    pub direction: i8,
    /// Joint angle at step position 0 (power-up), deg.
    pub zero_deg: f64,
    /// Soft limit: lowest joint angle, deg.
    pub min_deg: f64,
    /// Soft limit: highest joint angle, deg.
    pub max_deg: f64,
    /// Joint direction towards the homing switch: 1, −1, or 0 (no
    /// switch), whole.
    pub home_dir: f64,
    /// Joint angle where the homing switch closes, deg.
    pub home_deg: f64,
}

/// The stepper pan/tilt's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepperSettings {
    /// Motor full-step angle, deg.
    pub full_step_deg: f64,
    /// Driver microsteps per full step (whole).
    pub microsteps: f64,
    /// Highest joint speed of either axis, deg/s.
    pub max_speed_deg_s: f64,
    /// Joint acceleration limit, deg/s².
    pub accel_deg_s2: f64,
    /// grbl's junction deviation, deg of joint travel.
    pub junction_deviation_deg: f64,
    /// STEP pulse width, µs.
    pub pulse_us: f64,
    /// DIR stable before the rising STEP edge, µs.
    pub dir_setup_us: f64,
    /// ENABLE polarity: 1 active high, 0 active low.
    pub enable_active_high: f64,
    /// Drivers released after this long at rest, ms (0: always held).
    pub idle_release_ms: f64,
    /// Homing seek (and pull-off) speed, deg/s.
    pub home_seek_deg_s: f64,
    /// Homing latch speed, deg/s.
    pub home_latch_deg_s: f64,
    /// Homing back-off and pull-off distance, deg.
    pub home_pulloff_deg: f64,
    /// Pan (yaw) axis.
    pub pan: StepperAxisSettings,
    /// Tilt (pitch) axis.
    pub tilt: StepperAxisSettings,
}

impl Default for StepperSettings {
    /// The seed's pan/tilt: 1.8° at 32 microsteps (0.05625° per step),
    /// ±60° soft limits, 90 °/s, 900 °/s², junction deviation 0.01°,
    /// 2.5 µs pulses, 5 µs DIR setup, ENABLE active low, always held.
    fn default() -> Self {
        let axis = StepperAxisSettings {
            direction: 1,
            zero_deg: 0.0,
            min_deg: -60.0,
            max_deg: 60.0,
            home_dir: 0.0,
            home_deg: 0.0,
        };
        Self {
            full_step_deg: SEED_FULL_STEP_DEG,
            microsteps: SEED_MICROSTEPS as f64,
            max_speed_deg_s: 90.0,
            accel_deg_s2: 900.0,
            junction_deviation_deg: 0.01,
            pulse_us: 2.5,
            dir_setup_us: 5.0,
            enable_active_high: 0.0,
            idle_release_ms: 0.0,
            home_seek_deg_s: 20.0,
            home_latch_deg_s: 2.0,
            home_pulloff_deg: 2.0,
            pan: axis,
            tilt: axis,
        }
    }
}

impl StepperSettings {
    /// Degrees per microstep.
    pub fn deg_per_step(&self) -> f64 {
        self.full_step_deg / self.microsteps.max(1.0)
    }

    /// Rules between the stepper parameters: the step rate at the top
    /// speed within [`MAX_STEP_RATE_STEPS_S`] with room for the DIR setup
    /// and the pulse in one step period, limits in order, zero inside.
    pub(super) fn validate(&self) -> Result<(), SettingsError> {
        let rate = self.max_speed_deg_s / self.deg_per_step();
        if !(MIN_RATE_STEPS_PER_S..=MAX_STEP_RATE_STEPS_S).contains(&rate) {
            return Err(SettingsError::Rejected(
                "stepper.max_speed_deg_s must be 1..50000 steps/s at this step angle",
            ));
        }
        let accel = self.accel_deg_s2 / self.deg_per_step();
        if !(MIN_ACCEL_STEPS_PER_S2..=MAX_ACCEL_STEPS_PER_S2).contains(&accel) {
            return Err(SettingsError::Rejected(
                "stepper.accel_deg_s2 must be 1..1e9 steps/s^2 at this step angle",
            ));
        }
        if (self.pulse_us + self.dir_setup_us) * rate >= 1.0e6 {
            return Err(SettingsError::Rejected(
                "stepper pulse + DIR setup do not fit the step period at max speed",
            ));
        }
        for speed in [self.home_seek_deg_s, self.home_latch_deg_s] {
            let rate = speed / self.deg_per_step();
            if !(MIN_RATE_STEPS_PER_S..=MAX_STEP_RATE_STEPS_S).contains(&rate) {
                return Err(SettingsError::Rejected(
                    "stepper homing speeds must be 1..50000 steps/s at this step angle",
                ));
            }
        }
        for axis in [&self.pan, &self.tilt] {
            if axis.min_deg >= axis.max_deg {
                return Err(SettingsError::Rejected(
                    "stepper min_deg must be below max_deg",
                ));
            }
        }
        Ok(())
    }
}
