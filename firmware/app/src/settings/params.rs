//! The parameter table: name, unit, range and storage of every parameter.

use core::fmt;

use super::{LaserMode, Settings};
use crate::cli::error::CommandError;
use crate::text::Shortest;
use kinematics_core::error_model::COEF_LIMITS;

/// How a parameter's value is stored.
#[derive(Clone, Copy)]
pub(super) enum Slot {
    Real(fn(&mut Settings) -> &mut f64),
    Count(fn(&mut Settings) -> &mut u8),
    Sign(fn(&mut Settings) -> &mut i8),
    Laser,
    // Only in builds with galvo output.
    #[cfg_attr(not(feature = "galvo"), allow(dead_code))]
    Planner,
}

/// The precision a parameter's value is used in by the code that reads
/// it (the value is stored as f64 either way).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// Used as f64 (or as a whole number).
    F64,
    /// Converted to f32 where it is used (galvo geometry and DAC mapping,
    /// marking): it must stay finite and, when non-zero, non-zero in f32.
    F32,
}

/// Description of one parameter. Every value is checked against
/// `min..=max` (and `min_magnitude`) before it is stored; the ranges are
/// the physically meaningful ones for the hardware of SPEC §2, so a value
/// that passes cannot degenerate (divide by ~0, overflow or vanish) in the
/// precision it is used in.
#[derive(Clone, Copy)]
pub struct ParamSpec {
    /// Name used by `set` / `get`.
    pub name: &'static str,
    /// Lowest accepted value (in the parameter's unit).
    pub min: f64,
    /// Highest accepted value (in the parameter's unit).
    pub max: f64,
    /// Smallest accepted magnitude `|value|` (0: none). For parameters
    /// whose sign is a direction (DAC scales), so neither sign can come
    /// close to 0.
    pub min_magnitude: f64,
    /// Precision the value is used in.
    pub precision: Precision,
    /// What it is, with unit.
    pub help: &'static str,
    pub(super) slot: Slot,
}

macro_rules! real {
    ($name:literal, $min:expr, $max:expr, $help:literal, |$s:ident| $place:expr) => {
        real!($name, $min, $max, Precision::F64, $help, |$s| $place)
    };
    ($name:literal, $min:expr, $max:expr, $precision:expr, $help:literal, |$s:ident| $place:expr) => {
        ParamSpec {
            name: $name,
            min: $min,
            max: $max,
            min_magnitude: 0.0,
            precision: $precision,
            help: $help,
            slot: Slot::Real(|$s| &mut $place),
        }
    };
}

/// A whole-number parameter (ids, counts).
macro_rules! count {
    ($name:literal, $min:expr, $max:expr, $help:literal, |$s:ident| $place:expr) => {
        choice!($name, $min, $max, $help, Slot::Count(|$s| &mut $place))
    };
}

/// A parameter that is one of a few codes (`slot` decides which).
macro_rules! choice {
    ($name:literal, $min:expr, $max:expr, $help:literal, $slot:expr) => {
        ParamSpec {
            name: $name,
            min: $min,
            max: $max,
            min_magnitude: 0.0,
            precision: Precision::F64,
            help: $help,
            slot: $slot,
        }
    };
}

/// Error-model coefficients (SPEC §5): `Δ = c0 + c1·x + c2·y + c3·x² +
/// c4·x·y + c5·y²` with x, y, Δ in mm. Ranges from
/// [`kinematics_core::error_model::COEF_LIMITS`] (shared with `cargo xtask
/// calib fit`): c0 ±100 mm, c1/c2 ±1 mm/mm, c3..c5 ±0.01 1/mm.
macro_rules! err_coef {
    ($name:literal, $axis:ident, $i:literal, $help:literal) => {
        real!($name, -COEF_LIMITS[$i], COEF_LIMITS[$i], $help, |s| s.$axis
            [$i])
    };
}

/// Smallest |galvo DAC scale|, codes/rad: 4096 codes over ±45° of mirror.
pub const MIN_CODES_PER_RAD: f64 = 1_000.0;
/// Largest |galvo DAC scale|, codes/rad: 4096 codes over ±1° of mirror.
pub const MAX_CODES_PER_RAD: f64 = 120_000.0;

/// The parameter table (also the order of `params` and of the saved record).
pub static PARAMS: &[ParamSpec] = &[
    real!(
        "oq_cm",
        5.0,
        500.0,
        "gimbal centre to board distance OQ, cm",
        |s| s.oq_cm
    ),
    real!("ol_cm", 0.0, 20.0, "laser axis offset OL, cm", |s| s.ol_cm),
    real!("grid.pitch_cm", 0.1, 20.0, "grid pitch, cm", |s| s
        .grid_pitch_cm),
    count!("grid.cols", 2.0, 40.0, "grid columns (even), cells", |s| s
        .grid_cols),
    count!("grid.rows", 2.0, 40.0, "grid rows (even), cells", |s| s
        .grid_rows),
    real!(
        "grid.x_offset_cm",
        -100.0,
        100.0,
        "board x offset of the grid origin, cm",
        |s| s.x_offset_cm
    ),
    real!(
        "grid.y_offset_cm",
        -100.0,
        100.0,
        "board y offset of the grid origin, cm",
        |s| s.y_offset_cm
    ),
    real!(
        "board.roll_deg",
        -10.0,
        10.0,
        "board rotation about global x, deg",
        |s| s.board_roll_deg
    ),
    real!(
        "dwell_ms",
        0.0,
        60_000.0,
        "dwell per point after arrival, ms",
        |s| s.dwell_ms
    ),
    real!(
        "servo.speed_deg_s",
        1.0,
        750.0,
        "servo travel speed, deg/s",
        |s| s.servo_speed_deg_s
    ),
    real!(
        "servo.deadband_deg",
        0.1,
        10.0,
        "arrival deadband, deg",
        |s| s.deadband_deg
    ),
    real!(
        "path.step_cm",
        0.01,
        5.0,
        "line/circle/rect interpolation step, cm",
        |s| s.path_step_cm
    ),
    count!("yaw.id", 0.0, 253.0, "yaw servo bus id", |s| s.yaw.id),
    choice!(
        "yaw.dir",
        -1.0,
        1.0,
        "yaw direction, +1 or -1",
        Slot::Sign(|s| &mut s.yaw.direction)
    ),
    real!("yaw.scale", 0.5, 2.0, "yaw servo deg per joint deg", |s| s
        .yaw
        .scale),
    real!(
        "yaw.zero_deg",
        -90.0,
        90.0,
        "yaw servo angle at joint 0, deg",
        |s| s.yaw.zero_deg
    ),
    real!(
        "yaw.min_deg",
        -180.0,
        180.0,
        "yaw servo lower limit, deg",
        |s| s.yaw.min_deg
    ),
    real!(
        "yaw.max_deg",
        -180.0,
        180.0,
        "yaw servo upper limit, deg",
        |s| s.yaw.max_deg
    ),
    count!("pitch.id", 0.0, 253.0, "pitch servo bus id", |s| s.pitch.id),
    choice!(
        "pitch.dir",
        -1.0,
        1.0,
        "pitch direction, +1 or -1",
        Slot::Sign(|s| &mut s.pitch.direction)
    ),
    real!(
        "pitch.scale",
        0.5,
        2.0,
        "pitch servo deg per joint deg",
        |s| s.pitch.scale
    ),
    real!(
        "pitch.zero_deg",
        -90.0,
        90.0,
        "pitch servo angle at joint 0, deg",
        |s| s.pitch.zero_deg
    ),
    real!(
        "pitch.min_deg",
        -180.0,
        180.0,
        "pitch servo lower limit, deg",
        |s| s.pitch.min_deg
    ),
    real!(
        "pitch.max_deg",
        -180.0,
        180.0,
        "pitch servo upper limit, deg",
        |s| s.pitch.max_deg
    ),
    choice!(
        "laser.mode",
        0.0,
        2.0,
        "0 auto, 1 dwell, 2 off",
        Slot::Laser
    ),
    err_coef!("err.dx.c0", err_dx, 0, "error-model constant c0, mm"),
    err_coef!(
        "err.dx.c1",
        err_dx,
        1,
        "error-model coefficient c1 of x, mm/mm"
    ),
    err_coef!(
        "err.dx.c2",
        err_dx,
        2,
        "error-model coefficient c2 of y, mm/mm"
    ),
    err_coef!(
        "err.dx.c3",
        err_dx,
        3,
        "error-model coefficient c3 of x^2, 1/mm"
    ),
    err_coef!(
        "err.dx.c4",
        err_dx,
        4,
        "error-model coefficient c4 of x*y, 1/mm"
    ),
    err_coef!(
        "err.dx.c5",
        err_dx,
        5,
        "error-model coefficient c5 of y^2, 1/mm"
    ),
    err_coef!("err.dy.c0", err_dy, 0, "error-model constant c0, mm"),
    err_coef!(
        "err.dy.c1",
        err_dy,
        1,
        "error-model coefficient c1 of x, mm/mm"
    ),
    err_coef!(
        "err.dy.c2",
        err_dy,
        2,
        "error-model coefficient c2 of y, mm/mm"
    ),
    err_coef!(
        "err.dy.c3",
        err_dy,
        3,
        "error-model coefficient c3 of x^2, 1/mm"
    ),
    err_coef!(
        "err.dy.c4",
        err_dy,
        4,
        "error-model coefficient c4 of x*y, 1/mm"
    ),
    err_coef!(
        "err.dy.c5",
        err_dy,
        5,
        "error-model coefficient c5 of y^2, 1/mm"
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.d_mm",
        50.0,
        5000.0,
        Precision::F32,
        "galvo Y mirror to board distance d, mm",
        |s| s.galvo.d_mm
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.e_mm",
        0.0,
        100.0,
        Precision::F32,
        "galvo mirror separation e, mm",
        |s| s.galvo.e_mm
    ),
    #[cfg(feature = "galvo")]
    ParamSpec {
        name: "galvo.x_codes_per_rad",
        min: -MAX_CODES_PER_RAD,
        max: MAX_CODES_PER_RAD,
        min_magnitude: MIN_CODES_PER_RAD,
        precision: Precision::F32,
        help: "galvo X DAC codes/rad, |v| >= 1000, sign = direction",
        slot: Slot::Real(|s| &mut s.galvo.x_codes_per_rad),
    },
    #[cfg(feature = "galvo")]
    real!(
        "galvo.x_offset_code",
        0.0,
        4095.0,
        Precision::F32,
        "galvo X DAC code at angle 0",
        |s| s.galvo.x_offset_code
    ),
    #[cfg(feature = "galvo")]
    ParamSpec {
        name: "galvo.y_codes_per_rad",
        min: -MAX_CODES_PER_RAD,
        max: MAX_CODES_PER_RAD,
        min_magnitude: MIN_CODES_PER_RAD,
        precision: Precision::F32,
        help: "galvo Y DAC codes/rad, |v| >= 1000, sign = direction",
        slot: Slot::Real(|s| &mut s.galvo.y_codes_per_rad),
    },
    #[cfg(feature = "galvo")]
    real!(
        "galvo.y_offset_code",
        0.0,
        4095.0,
        Precision::F32,
        "galvo Y DAC code at angle 0",
        |s| s.galvo.y_offset_code
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.kt_nm_per_a",
        1e-4,
        1.0,
        "galvo motor torque constant Kt, N*m/A",
        |s| s.galvo.kt_nm_per_a
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.j_kg_m2",
        1e-10,
        1e-4,
        "galvo rotor+mirror inertia J, kg*m^2",
        |s| s.galvo.j_kg_m2
    ),
    #[cfg(feature = "galvo")]
    real!("galvo.l_h", 1e-6, 0.1, "galvo coil inductance L, H", |s| s
        .galvo
        .l_h),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.r_ohm",
        0.1,
        100.0,
        "galvo coil resistance R, ohm",
        |s| s.galvo.r_ohm
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.u_max_v",
        1.0,
        100.0,
        "galvo drive voltage limit Umax, V",
        |s| s.galvo.u_max_v
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.ts_us",
        5.0,
        1000.0,
        "galvo DAC sample period, us",
        |s| s.galvo.sample_period_us
    ),
    #[cfg(feature = "galvo")]
    choice!(
        "galvo.planner",
        0.0,
        1.0,
        "galvo jump planner: 0 optimal, 1 seed",
        Slot::Planner
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.laser_on_delay_us",
        0.0,
        10_000.0,
        "galvo hold before laser on after a jump, us",
        |s| s.galvo.laser_on_delay_us
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.laser_off_delay_us",
        0.0,
        10_000.0,
        "galvo hold after laser off before a jump, us",
        |s| s.galvo.laser_off_delay_us
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.mark_speed_mm_s",
        1.0,
        20_000.0,
        "galvo marking speed of paths, mm/s",
        |s| s.galvo.mark_speed_mm_s
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.mark_accel_mm_s2",
        100.0,
        1.0e8,
        Precision::F32,
        "galvo marking acceleration, mm/s^2",
        |s| s.galvo.mark_accel_mm_s2
    ),
];

/// Finds a parameter by name (case-insensitive).
pub fn find_param(name: &str) -> Option<&'static ParamSpec> {
    PARAMS.iter().find(|p| p.name.eq_ignore_ascii_case(name))
}

/// Checks one value against its parameter's range and kind.
pub(super) fn check_value(param: &ParamSpec, value: f64) -> Result<(), CommandError> {
    if !value.is_finite() || value < param.min || value > param.max {
        return Err(CommandError::OutOfRange {
            what: param.name,
            min: param.min,
            max: param.max,
        });
    }
    if value.abs() < param.min_magnitude {
        return Err(CommandError::Rejected(
            "value too close to 0 (see `params` for the smallest magnitude)",
        ));
    }
    if param.precision == Precision::F32 && !survives_f32(value) {
        return Err(CommandError::Rejected("value not representable in f32"));
    }
    // In range, so the cast is exact for every whole value.
    let whole = (value as i64) as f64 == value;
    match param.slot {
        Slot::Real(_) => Ok(()),
        Slot::Count(_) if !whole => Err(CommandError::Rejected("value must be a whole number")),
        Slot::Sign(_) if value != 1.0 && value != -1.0 => {
            Err(CommandError::Rejected("direction must be 1 or -1"))
        }
        Slot::Planner if value != 0.0 && value != 1.0 => {
            Err(CommandError::Rejected("galvo.planner must be 0 or 1"))
        }
        Slot::Laser if LaserMode::from_code(value).is_none() => {
            Err(CommandError::Rejected("laser.mode must be 0, 1 or 2"))
        }
        _ => Ok(()),
    }
}

/// Whether `value` keeps its meaning as f32: finite, and non-zero unless
/// it is 0 (the ranges keep every accepted value far from both limits;
/// this is the check that they do).
pub(super) fn survives_f32(value: f64) -> bool {
    let narrow = value as f32;
    narrow.is_finite() && (narrow != 0.0 || value == 0.0)
}

/// Format of `get`/`params` lines: `name = value  # help [min, max]`.
pub struct ParamLine<'a>(pub &'a ParamSpec, pub f64);

impl fmt::Display for ParamLine<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} = {}  # {} [{}, {}]",
            self.0.name,
            Shortest(self.1),
            self.0.help,
            Shortest(self.0.min),
            Shortest(self.0.max)
        )
    }
}
