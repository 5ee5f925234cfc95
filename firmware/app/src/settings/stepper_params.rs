//! The stepper pan/tilt's rows of the parameter table (ids 160–183; the
//! settings themselves, and why they are stored as they are, in
//! `stepper.rs`).

use super::spec::{ParamSpec, Precision, Slot, real};
use super::values::Settings;

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
