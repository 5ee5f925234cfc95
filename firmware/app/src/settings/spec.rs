//! What describes a parameter ([`ParamSpec`]): its stable id, name, range,
//! precision and where it is stored; the value checks every stored value
//! passes; the `get`/`params` line. The table itself is in `params.rs`.

use core::fmt;

use super::error::SettingsError;
use super::values::{LaserMode, Settings};
use crate::text::{Interval, Shortest};

/// How a parameter's value is stored.
#[derive(Clone, Copy)]
pub(crate) enum Slot {
    Real(fn(&mut Settings) -> &mut f64),
    /// A whole number stored as f64.
    Whole(fn(&mut Settings) -> &mut f64),
    Count(fn(&mut Settings) -> &mut u8),
    /// A baud rate of the PELCO port (one of `PELCO_BAUDS`), stored as f64.
    Baud(fn(&mut Settings) -> &mut f64),
    Sign(fn(&mut Settings) -> &mut i8),
    Laser,
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
    /// Stable number of the parameter (like grbl's `$N`): the key of its
    /// value in the saved record. Never changes and is never reused; see
    /// the numbering in `params.rs`.
    pub id: u16,
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
    pub(crate) slot: Slot,
}

/// A real-valued parameter: `real!(id, name, min, max, [precision,] help,
/// |s| place)`.
macro_rules! real {
    ($id:literal, $name:literal, $min:expr, $max:expr, $help:literal, |$s:ident| $place:expr) => {
        real!($id, $name, $min, $max, Precision::F64, $help, |$s| $place)
    };
    ($id:literal, $name:literal, $min:expr, $max:expr, $precision:expr, $help:literal, |$s:ident| $place:expr) => {
        ParamSpec {
            id: $id,
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
    ($id:literal, $name:literal, $min:expr, $max:expr, $help:literal, |$s:ident| $place:expr) => {
        choice!($id, $name, $min, $max, $help, Slot::Count(|$s| &mut $place))
    };
}

/// A parameter that is one of a few codes (`slot` decides which).
macro_rules! choice {
    ($id:literal, $name:literal, $min:expr, $max:expr, $help:literal, $slot:expr) => {
        ParamSpec {
            id: $id,
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
    ($id:literal, $name:literal, $axis:ident, $i:literal) => {
        ParamSpec {
            id: $id,
            name: $name,
            min: -COEF_LIMITS[$i],
            max: COEF_LIMITS[$i],
            min_magnitude: 0.0,
            precision: Precision::F64,
            help: COEF_HELP[$i],
            slot: Slot::Real(|s| &mut s.$axis[$i]),
        }
    };
}

pub(crate) use {choice, count, err_coef, real};

/// What error-model coefficient `i` multiplies, with its unit.
pub(crate) const COEF_HELP: [&str; 6] = [
    "error-model constant c0, mm",
    "error-model coefficient c1 of x, mm/mm",
    "error-model coefficient c2 of y, mm/mm",
    "error-model coefficient c3 of x^2, 1/mm",
    "error-model coefficient c4 of x*y, 1/mm",
    "error-model coefficient c5 of y^2, 1/mm",
];

/// Checks one value against its parameter's range and kind.
pub(crate) fn check_value(param: &ParamSpec, value: f64) -> Result<(), SettingsError> {
    if !value.is_finite() || value < param.min || value > param.max {
        return Err(SettingsError::OutOfRange {
            what: param.name,
            min: param.min,
            max: param.max,
        });
    }
    if value.abs() < param.min_magnitude {
        return Err(SettingsError::Rejected(
            "value too close to 0 (see `params` for the smallest magnitude)",
        ));
    }
    if param.precision == Precision::F32 && !survives_f32(value) {
        return Err(SettingsError::Rejected("value not representable in f32"));
    }
    // In range, so the cast is exact for every whole value.
    let whole = (value as i64) as f64 == value;
    match param.slot {
        Slot::Real(_) => Ok(()),
        Slot::Baud(_) if !super::pelco::is_pelco_baud(value) => Err(SettingsError::Rejected(
            "pelco.baud must be 2400, 4800, 9600 or 19200",
        )),
        Slot::Count(_) | Slot::Whole(_) if !whole => {
            Err(SettingsError::Rejected("value must be a whole number"))
        }
        Slot::Sign(_) if value != 1.0 && value != -1.0 => {
            Err(SettingsError::Rejected("direction must be 1 or -1"))
        }
        Slot::Planner if value != 0.0 && value != 1.0 => {
            Err(SettingsError::Rejected("galvo.planner must be 0 or 1"))
        }
        Slot::Laser if LaserMode::from_code(value).is_none() => {
            Err(SettingsError::Rejected("laser.mode must be 0, 1 or 2"))
        }
        _ => Ok(()),
    }
}

/// Whether `value` keeps its meaning as f32: finite, and non-zero unless
/// it is 0 (the ranges keep every accepted value far from both limits;
/// this is the check that they do).
pub(crate) fn survives_f32(value: f64) -> bool {
    let narrow = value as f32;
    narrow.is_finite() && (narrow != 0.0 || value == 0.0)
}

/// Format of `get`/`params` lines: `name = value  # help [min, max]`.
pub struct ParamLine<'a>(pub &'a ParamSpec, pub f64);

impl fmt::Display for ParamLine<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} = {}  # {} {}",
            self.0.name,
            Shortest(self.1),
            self.0.help,
            Interval(self.0.min, self.0.max)
        )
    }
}
