//! A stroke in the unit it was built in: its start and its segments
//! (types only, shared by [`Figure`](super::Figure) and
//! [`StrokeCm`](super::StrokeCm)).

use kinematics_core::Rotation;

/// One piece of a stroke, in the stroke's unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Segment {
    /// Straight line to `to`.
    Line {
        /// End point `[x, y]`.
        to: [f64; 2],
    },
    /// Circular arc to `end` about `centre`; `end` equal to the start is a
    /// full circle.
    Arc {
        /// End point `[x, y]`.
        end: [f64; 2],
        /// Centre `[x, y]`.
        centre: [f64; 2],
        /// Direction.
        rotation: Rotation,
    },
}

/// Most segments of one stroke.
pub(super) const STROKE_SEGMENTS: usize = 4;

/// Segments of one stroke.
pub type Segments = heapless::Vec<Segment, STROKE_SEGMENTS>;

/// A stroke: drawn without a break from `start` through its segments, in
/// the [`Unit`](crate::domain::units::Unit) it was built in.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    /// Start point `[x, y]`.
    pub start: [f64; 2],
    /// What is drawn from the start, in order.
    pub segments: Segments,
}

impl Stroke {
    /// Straight lines from `start` through `points`.
    pub(super) fn lines(start: [f64; 2], points: impl IntoIterator<Item = [f64; 2]>) -> Self {
        Self {
            start,
            segments: points.into_iter().map(|to| Segment::Line { to }).collect(),
        }
    }

    /// The rectangle through opposite corners `a`, `b`, from `a`.
    pub(super) fn rect(a: [f64; 2], b: [f64; 2]) -> Self {
        Self::lines(a, [[b[0], a[1]], b, [a[0], b[1]], a])
    }

    /// The full circle about `centre` of radius `radius` from its top.
    pub(super) fn circle(centre: [f64; 2], radius: f64, rotation: Rotation) -> Self {
        let top = [centre[0], centre[1] + radius];
        Self {
            start: top,
            segments: Segments::from_iter([Segment::Arc {
                end: top,
                centre,
                rotation,
            }]),
        }
    }
}
