//! The crate's one error type.

use core::fmt;

use crate::numeric::NonFinite;

/// A gimbal joint (servo axis).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Joint {
    /// Yaw α, rotation about the global z axis.
    Yaw,
    /// Pitch β, rotation about the yawed horizontal axis.
    Pitch,
}

impl Joint {
    /// Lower-case name (`"yaw"`, `"pitch"`).
    pub fn name(self) -> &'static str {
        match self {
            Joint::Yaw => "yaw",
            Joint::Pitch => "pitch",
        }
    }
}

/// Everything that can go wrong in this crate. Functions document which
/// variants they return; none of them panics or returns NaN instead.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Error {
    /// An input (named) is NaN or infinite.
    NonFinite {
        /// Which input, e.g. `"x_cm"`.
        what: &'static str,
    },
    /// A configuration value is out of its domain (e.g. a zero scale).
    InvalidConfig {
        /// What is wrong, e.g. `"ol_cm must be >= 0"`.
        what: &'static str,
    },
    /// The target is within the laser offset circle: no beam offset by
    /// `OL` from the gimbal centre can pass through it.
    InsideOffsetCircle,
    /// The board (or the target) is not in front of the gimbal (`x_g <= 0`).
    BehindGimbal,
    /// The beam (or galvo deflection) is parallel to the board or points
    /// away from it, so it has no spot on the board.
    MissesBoard,
    /// A joint angle maps to a servo angle outside the servo's limits.
    JointLimit {
        /// Which joint.
        joint: Joint,
        /// Servo angle the joint angle maps to, degrees.
        servo_deg: f64,
        /// Lower servo limit, degrees.
        min_deg: f64,
        /// Upper servo limit, degrees.
        max_deg: f64,
    },
    /// A stepper angle needs more microsteps than an `i32` holds.
    StepsOutOfRange,
    /// A grid index outside the configured grid.
    GridIndexOutOfRange {
        /// Column index.
        xi: i16,
        /// Row index.
        yi: i16,
    },
    /// A DAC code above the converter's full scale (4095 for 12 bits).
    DacCodeOutOfRange {
        /// The code given.
        code: u16,
    },
    /// A path would need more interpolation steps than supported.
    TooManySteps,
    /// A path is shorter than it must be (e.g. a circle radius below one step).
    PathTooShort,
    /// An arc's end point is not on the circle through its start point
    /// (radii differ by more than half a step).
    EndNotOnCircle,
    /// Fewer measured points than the model has coefficients (6).
    TooFewPoints {
        /// Number of points given.
        n: usize,
    },
    /// The measured points do not determine the quadratic (collinear,
    /// repeated, or on one conic).
    DegeneratePoints,
    /// Compensation (inverse of the error model) did not converge.
    NotConverged,
    /// A measured point (0-based `index`) has a coordinate or error beyond
    /// [`crate::error_model::MAX_MEASURED_MM`] (10 m): no board is that
    /// large, and the quadratic of such values cannot be represented.
    MeasurementOutOfRange {
        /// 0-based index of the point.
        index: usize,
        /// Which value, e.g. `"x_mm"`.
        what: &'static str,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::NonFinite { what } => write!(f, "{what} is not a finite number"),
            Error::InvalidConfig { what } => write!(f, "invalid configuration: {what}"),
            Error::InsideOffsetCircle => {
                f.write_str("target is inside the laser offset circle (distance <= OL)")
            }
            Error::BehindGimbal => f.write_str("target is behind the gimbal"),
            Error::MissesBoard => f.write_str("beam does not hit the board"),
            Error::JointLimit {
                joint,
                servo_deg,
                min_deg,
                max_deg,
            } => {
                write!(f, "{} servo angle ", joint.name())?;
                write_hundredths(f, servo_deg)?;
                f.write_str(" deg is outside its limits [")?;
                write_hundredths(f, min_deg)?;
                f.write_str(", ")?;
                write_hundredths(f, max_deg)?;
                f.write_str("] deg")
            }
            Error::StepsOutOfRange => f.write_str("stepper angle out of the i32 microstep range"),
            Error::GridIndexOutOfRange { xi, yi } => {
                let (xi, yi) = (Int(xi.into()), Int(yi.into()));
                write!(f, "grid index ({xi}, {yi}) is outside the grid")
            }
            Error::DacCodeOutOfRange { code } => {
                let code = u32::from(code);
                write!(f, "DAC code {code} is above full scale")
            }
            Error::TooManySteps => f.write_str("path needs too many interpolation steps"),
            Error::PathTooShort => f.write_str("path is shorter than one step"),
            Error::EndNotOnCircle => f.write_str("arc end point is not on the circle"),
            Error::TooFewPoints { n } => {
                write!(f, "need at least 6 measured points, got {n}")
            }
            Error::DegeneratePoints => {
                f.write_str("measured points are degenerate (collinear, repeated or on one conic)")
            }
            Error::NotConverged => f.write_str("error-model compensation did not converge"),
            Error::MeasurementOutOfRange { index, what } => write!(
                f,
                "measured point {} has {what} beyond +-10000 mm (10 m)",
                index + 1
            ),
        }
    }
}

impl core::error::Error for Error {}

/// A signed integer as sign and magnitude through `u64`'s writer. Each
/// integer type's own `Display` is 100–280 B of the firmware's flash;
/// messages (here and laser-app's replies, `laser_app::text::Int`) print
/// signed values through this and unsigned ones as `u32` or `u64`, the
/// writers linked anyway.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Int(pub i64);

impl fmt::Display for Int {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0 < 0 {
            f.write_str("-")?;
        }
        write!(f, "{}", self.0.unsigned_abs())
    }
}

/// Writes `v` with two decimals by integer arithmetic: the firmware links
/// no `core` float formatting (its flash budget), so neither does this
/// crate's `Display`.
fn write_hundredths(f: &mut fmt::Formatter<'_>, v: f64) -> fmt::Result {
    let hundredths = libm::round(libm::fabs(v) * 100.0);
    if !hundredths.is_finite() || hundredths >= 1e15 {
        return f.write_str(if v.is_nan() { "NaN" } else { "out of range" });
    }
    let units = hundredths as u64;
    let sign = if v < 0.0 && units != 0 { "-" } else { "" };
    write!(f, "{sign}{}.{:02}", units / 100, units % 100)
}

impl From<NonFinite> for Error {
    fn from(e: NonFinite) -> Self {
        Error::NonFinite { what: e.name }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::string::ToString;

    #[test]
    fn display_names_the_problem() {
        assert_eq!(
            Error::NonFinite { what: "x_cm" }.to_string(),
            "x_cm is not a finite number"
        );
        let limit = Error::JointLimit {
            joint: Joint::Pitch,
            servo_deg: 140.0,
            min_deg: -135.0,
            max_deg: 135.0,
        };
        assert_eq!(
            limit.to_string(),
            "pitch servo angle 140.00 deg is outside its limits [-135.00, 135.00] deg"
        );
        assert_eq!(
            Error::TooFewPoints { n: 3 }.to_string(),
            "need at least 6 measured points, got 3"
        );
    }

    #[test]
    fn a_non_finite_value_keeps_its_name() {
        let e: Error = crate::numeric::finite(f64::NAN, "a").unwrap_err().into();
        assert_eq!(e, Error::NonFinite { what: "a" });
        let e: Error = crate::numeric::finite(f64::NEG_INFINITY, "b")
            .unwrap_err()
            .into();
        assert_eq!(e, Error::NonFinite { what: "b" });
    }
}
