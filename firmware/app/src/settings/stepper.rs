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

use super::Settings;
use super::error::SettingsError;
use super::spec::{ParamSpec, Precision, Slot, real};
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

/// The stepper's rows of the parameter table (ids ascending).
pub(super) const STEPPER_PARAMS: [ParamSpec; 24] = [
    real!(
        160,
        "stepper.full_step_deg",
        0.1,
        15.0,
        "stepper motor full-step angle, deg",
        |s| s.stepper.full_step_deg
    ),
    whole(
        161,
        "stepper.microsteps",
        1.0,
        256.0,
        "stepper driver microsteps per full step",
        |s| &mut s.stepper.microsteps,
    ),
    real!(
        162,
        "stepper.max_speed_deg_s",
        0.1,
        3600.0,
        "stepper max joint speed, deg/s",
        |s| s.stepper.max_speed_deg_s
    ),
    real!(
        163,
        "stepper.accel_deg_s2",
        1.0,
        1.0e6,
        "stepper joint acceleration, deg/s^2",
        |s| s.stepper.accel_deg_s2
    ),
    real!(
        164,
        "stepper.junction_deg",
        0.0,
        10.0,
        "stepper junction deviation, deg",
        |s| s.stepper.junction_deviation_deg
    ),
    real!(
        165,
        "stepper.pulse_us",
        0.5,
        100.0,
        "stepper STEP pulse width, us",
        |s| s.stepper.pulse_us
    ),
    real!(
        166,
        "stepper.dir_setup_us",
        0.0,
        100.0,
        "stepper DIR setup before STEP, us",
        |s| s.stepper.dir_setup_us
    ),
    whole(
        167,
        "stepper.enable_high",
        0.0,
        1.0,
        "stepper ENABLE polarity: 1 active high, 0 low",
        |s| &mut s.stepper.enable_active_high,
    ),
    real!(
        168,
        "stepper.idle_release_ms",
        0.0,
        3.6e6,
        "stepper drivers released after rest, ms (0 held)",
        |s| s.stepper.idle_release_ms
    ),
    sign(
        169,
        "stepper.pan.dir",
        "stepper pan step direction, 1 or -1",
        |s| &mut s.stepper.pan.direction,
    ),
    real!(
        170,
        "stepper.pan.zero_deg",
        -180.0,
        180.0,
        "stepper pan joint angle at step 0, deg",
        |s| s.stepper.pan.zero_deg
    ),
    real!(
        171,
        "stepper.pan.min_deg",
        -180.0,
        180.0,
        "stepper pan soft limit low, deg",
        |s| s.stepper.pan.min_deg
    ),
    real!(
        172,
        "stepper.pan.max_deg",
        -180.0,
        180.0,
        "stepper pan soft limit high, deg",
        |s| s.stepper.pan.max_deg
    ),
    sign(
        173,
        "stepper.tilt.dir",
        "stepper tilt step direction, 1 or -1",
        |s| &mut s.stepper.tilt.direction,
    ),
    real!(
        174,
        "stepper.tilt.zero_deg",
        -90.0,
        90.0,
        "stepper tilt joint angle at step 0, deg",
        |s| s.stepper.tilt.zero_deg
    ),
    real!(
        175,
        "stepper.tilt.min_deg",
        -90.0,
        90.0,
        "stepper tilt soft limit low, deg",
        |s| s.stepper.tilt.min_deg
    ),
    real!(
        176,
        "stepper.tilt.max_deg",
        -90.0,
        90.0,
        "stepper tilt soft limit high, deg",
        |s| s.stepper.tilt.max_deg
    ),
    real!(
        177,
        "stepper.home_seek_deg_s",
        0.01,
        360.0,
        "stepper homing seek speed, deg/s",
        |s| s.stepper.home_seek_deg_s
    ),
    real!(
        178,
        "stepper.home_latch_deg_s",
        0.01,
        360.0,
        "stepper homing latch speed, deg/s",
        |s| s.stepper.home_latch_deg_s
    ),
    real!(
        179,
        "stepper.home_pulloff_deg",
        0.01,
        20.0,
        "stepper homing back-off/pull-off, deg",
        |s| s.stepper.home_pulloff_deg
    ),
    whole(
        180,
        "stepper.pan.home_dir",
        -1.0,
        1.0,
        "stepper pan switch direction: 1, -1, 0 none",
        |s| &mut s.stepper.pan.home_dir,
    ),
    real!(
        181,
        "stepper.pan.home_deg",
        -180.0,
        180.0,
        "stepper pan joint angle at the switch, deg",
        |s| s.stepper.pan.home_deg
    ),
    whole(
        182,
        "stepper.tilt.home_dir",
        -1.0,
        1.0,
        "stepper tilt switch direction: 1, -1, 0 none",
        |s| &mut s.stepper.tilt.home_dir,
    ),
    real!(
        183,
        "stepper.tilt.home_deg",
        -90.0,
        90.0,
        "stepper tilt joint angle at the switch, deg",
        |s| s.stepper.tilt.home_deg
    ),
];

/// A whole-number parameter stored as f64.
const fn whole(
    id: u16,
    name: &'static str,
    min: f64,
    max: f64,
    help: &'static str,
    place: fn(&mut Settings) -> &mut f64,
) -> ParamSpec {
    ParamSpec {
        id,
        name,
        min,
        max,
        min_magnitude: 0.0,
        precision: Precision::F64,
        help,
        slot: Slot::Whole(place),
    }
}

/// A direction, 1 or −1.
const fn sign(
    id: u16,
    name: &'static str,
    help: &'static str,
    place: fn(&mut Settings) -> &mut i8,
) -> ParamSpec {
    ParamSpec {
        id,
        name,
        min: -1.0,
        max: 1.0,
        min_magnitude: 0.0,
        precision: Precision::F64,
        help,
        slot: Slot::Sign(place),
    }
}
