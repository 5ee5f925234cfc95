//! Why a pattern or goto is refused, or a run stopped: the reasons the
//! checks give, in command-line text.

use kinematics_core as kc;

use super::point::PointCm;
use crate::text::Fixed;

/// Why a pattern (or goto) cannot run with the current settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PatternError {
    /// The path cannot be interpolated (radius below one step, too many
    /// steps, non-finite input).
    Path {
        /// Pattern name.
        pattern: &'static str,
        /// Why.
        error: kc::Error,
    },
    /// A point cannot be aimed at.
    Unreachable {
        /// Pattern name (`goto` for a single target).
        pattern: &'static str,
        /// Index of the first bad point.
        index: usize,
        /// The point, cm.
        point: PointCm,
        /// Why.
        error: kc::Error,
    },
    /// The pattern has no point on the configured grid.
    Empty {
        /// Pattern name.
        pattern: &'static str,
    },
    /// A point of the ideal figure between its interpolated points cannot
    /// be aimed at.
    FigureUnreachable {
        /// Pattern name.
        pattern: &'static str,
        /// The point, cm.
        point: PointCm,
        /// Why.
        error: kc::Error,
    },
    /// A point is outside the galvo's DAC range.
    OutsideGalvoRange {
        /// Pattern name (`goto` for a single target).
        pattern: &'static str,
        /// Index of the first bad point.
        index: usize,
        /// The point, cm.
        point: PointCm,
    },
    /// A path cannot be drawn by the selected actuator(s): paths run on
    /// one actuator at a time, and the tuning figure only on the galvo.
    PathActuator {
        /// Pattern name.
        pattern: &'static str,
    },
}

impl core::fmt::Display for PatternError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            PatternError::Path { pattern, error } => write!(f, "{pattern}: {error}"),
            PatternError::Unreachable {
                pattern,
                index,
                point,
                error,
            } => write!(
                f,
                "{pattern} point {index} ({}, {}) cm unreachable: {error}",
                Fixed::<2>(point.x_cm),
                Fixed::<2>(point.y_cm)
            ),
            PatternError::FigureUnreachable {
                pattern,
                point,
                error,
            } => write!(
                f,
                "{pattern} passes ({}, {}) cm, unreachable: {error}",
                Fixed::<2>(point.x_cm),
                Fixed::<2>(point.y_cm)
            ),
            PatternError::Empty { pattern } => write!(f, "{pattern} has no points on this grid"),
            PatternError::OutsideGalvoRange {
                pattern,
                index,
                point,
            } => write!(
                f,
                "{pattern} point {index} ({}, {}) cm is outside the galvo's range",
                Fixed::<2>(point.x_cm),
                Fixed::<2>(point.y_cm)
            ),
            PatternError::PathActuator { pattern } => write!(
                f,
                "{pattern}: paths run on one actuator at a time (tuning: galvo only); use target gimbal or galvo"
            ),
        }
    }
}
