//! The crate's one error type.

use core::fmt;

use kinematics_core::numeric::{NonFinite, finite};

/// Everything that can go wrong when building a model, planning a move,
/// queueing it or adding a path segment. Invalid input is always reported
/// with one of these, never with a panic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Error {
    /// A parameter or request value is NaN or infinite.
    NonFinite {
        /// Name of the offending value (SI unit in the name).
        name: &'static str,
    },
    /// A parameter that must be strictly positive is zero or negative.
    NotPositive {
        /// Name of the offending value.
        name: &'static str,
        /// The value that was given.
        value: f64,
    },
    /// The voltage limit cannot move the galvo at all (`u_max_v` ≤ 0).
    UmaxTooSmall {
        /// The voltage limit that was given, volts.
        u_max_v: f64,
    },
    /// The sample period is zero, negative or not finite.
    InvalidSamplePeriod {
        /// The sample period that was given, seconds.
        ts_s: f64,
    },
    /// The sampled model cannot be steered to every state with one input
    /// (e.g. the torsional resonance sampled at exactly half a period per
    /// sample).
    NotControllable,
    /// The target state cannot be reached exactly in this many samples (fewer
    /// samples than states, or a numerically singular reachability Gramian).
    NotReachable {
        /// The number of samples that was asked for.
        samples: usize,
    },
    /// The move needs more samples than the buffer offered for it.
    CapacityExceeded {
        /// Samples the move needs (a lower bound when `at_least`).
        needed: usize,
        /// Samples the caller's buffer can hold.
        capacity: usize,
    },
    /// The requested planner does not exist for this model (the time-optimal
    /// planner is for the rigid model).
    UnsupportedModel,
    /// A user-supplied bisection bracket `[t_min_s, t_max_s]` is empty, or its
    /// upper end is not a feasible move time.
    InvalidBracket {
        /// Lower end, seconds.
        t_min_s: f64,
        /// Upper end, seconds.
        t_max_s: f64,
    },
    /// An iterative solver did not converge (should not happen for valid
    /// parameters; reported instead of returning a wrong plan).
    NoConvergence,
    /// The integrator's move queue or sample ring has no room for this move.
    QueueFull,
    /// The integrator is still moving; it can only be re-seated when idle.
    IntegratorBusy,
    /// A plan made for a different sampled model than the integrator's.
    ModelMismatch,
    /// A queued move does not start where the previously queued move ends.
    DiscontinuousMove,
    /// A path segment was added while the look-ahead buffer is full.
    BufferFull,
    /// An arc's end point is not on the circle through its start point.
    ArcRadiusMismatch {
        /// Radius measured at the start point, mm.
        start_radius_mm: f64,
        /// Radius measured at the end point, mm.
        end_radius_mm: f64,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::NonFinite { name } => write!(f, "{name} is not a finite number"),
            Error::NotPositive { name, value } => {
                write!(f, "{name} must be positive (got {value})")
            }
            Error::UmaxTooSmall { u_max_v } => write!(
                f,
                "voltage limit {u_max_v} V is too small: it must be a positive, finite voltage"
            ),
            Error::InvalidSamplePeriod { ts_s } => {
                write!(f, "sample period {ts_s} s must be positive and finite")
            }
            Error::NotControllable => write!(
                f,
                "the sampled model is not controllable with this sample period"
            ),
            Error::NotReachable { samples } => write!(
                f,
                "the target state cannot be reached exactly in {samples} samples"
            ),
            Error::CapacityExceeded { needed, capacity } => write!(
                f,
                "the move needs {needed} samples but the buffer holds {capacity}"
            ),
            Error::UnsupportedModel => {
                write!(f, "the time-optimal planner supports the rigid model only")
            }
            Error::InvalidBracket { t_min_s, t_max_s } => write!(
                f,
                "bisection bracket [{t_min_s}, {t_max_s}] s is empty or its upper end is not feasible"
            ),
            Error::NoConvergence => write!(f, "the planner's solver did not converge"),
            Error::QueueFull => write!(f, "the integrator queue is full"),
            Error::IntegratorBusy => write!(f, "the integrator is still executing a move"),
            Error::ModelMismatch => write!(
                f,
                "the plan was made for a different sampled model than the integrator's"
            ),
            Error::DiscontinuousMove => write!(
                f,
                "the move does not start where the previously queued move ends"
            ),
            Error::BufferFull => write!(f, "the path planner buffer is full"),
            Error::ArcRadiusMismatch {
                start_radius_mm,
                end_radius_mm,
            } => write!(
                f,
                "arc end is not on the circle: start radius {start_radius_mm} mm, end radius {end_radius_mm} mm"
            ),
        }
    }
}

impl core::error::Error for Error {}

impl From<NonFinite> for Error {
    fn from(e: NonFinite) -> Self {
        Error::NonFinite { name: e.name }
    }
}

/// Checks that `value` is finite and strictly positive.
pub(crate) fn positive(value: f64, name: &'static str) -> Result<f64, Error> {
    let value = finite(value, name)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(Error::NotPositive { name, value })
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::string::ToString;

    #[test]
    fn display_names_the_value() {
        let e = Error::NotPositive {
            name: "r_ohm",
            value: -1.0,
        };
        assert_eq!(e.to_string(), "r_ohm must be positive (got -1)");
        let e = Error::CapacityExceeded {
            needed: 90,
            capacity: 64,
        };
        assert!(e.to_string().contains("90") && e.to_string().contains("64"));
    }

    #[test]
    fn validators() {
        assert_eq!(positive(2.0, "x"), Ok(2.0));
        assert_eq!(
            positive(0.0, "x"),
            Err(Error::NotPositive {
                name: "x",
                value: 0.0
            })
        );
        assert_eq!(positive(f64::NAN, "x"), Err(Error::NonFinite { name: "x" }));
        assert_eq!(
            finite(f64::INFINITY, "y").map_err(Error::from),
            Err(Error::NonFinite { name: "y" })
        );
        assert_eq!(finite(-3.0, "y"), Ok(-3.0));
    }
}
