//! The board curve of a move the stepper cuts into pieces ([`Curve`]) and
//! the cut in progress ([`PieceCut`]).

use kinematics_core::frames::BoardPoint;
use kinematics_core::numeric::clamp;
use kinematics_core::path::{Segment as BoardSegment, Shape};

use super::super::link::messages::MoveShape;

/// The board curve of a move being cut into pieces (kinematics-core's
/// shape, the gimbal sampler's point-at-parameter).
#[derive(Debug, Clone, Copy)]
pub(super) struct Curve(Shape);

impl Curve {
    /// The curve from `from` to `to` as `shape` says (`None`: travel).
    pub(super) fn of(from: BoardPoint, to: BoardPoint, shape: MoveShape) -> Option<Self> {
        let segment = match shape {
            MoveShape::Travel => return None,
            MoveShape::Line => BoardSegment::Line { from, to },
            MoveShape::Arc { centre, rotation } => BoardSegment::Arc {
                start: from,
                end: to,
                centre,
                rotation,
            },
        };
        Some(Curve(Shape::of(segment)))
    }

    /// The curve's shape.
    pub(super) fn shape(&self) -> Shape {
        self.0
    }

    /// The point a fraction `t` (0..=1) along the curve.
    pub(super) fn at(&self, t: f64) -> BoardPoint {
        self.0.point_at(t)
    }

    /// Pieces to start from: arcs in pieces of at most 22.5° (so a
    /// piece's midpoint tells its deviation; a full circle is not one
    /// piece from its start to itself).
    pub(super) fn fewest_pieces(&self) -> u32 {
        match self.0 {
            Shape::Line { .. } => 1,
            Shape::Arc { sweep_rad, .. } => {
                let wanted = libm::ceil(sweep_rad.abs() / (core::f64::consts::PI / 8.0));
                // ≤ 16 for |sweep| ≤ 2π: the cast is exact.
                (wanted as u32).max(1).next_power_of_two()
            }
        }
    }

    /// Distance of `p` from the curve (near it), cm.
    pub(super) fn distance_cm(&self, p: BoardPoint) -> f64 {
        match self.0 {
            Shape::Line { from, to } => distance_to_segment_cm(p, from, to),
            Shape::Arc {
                centre, radius_cm, ..
            } => (kinematics_core::numeric::hypot(p.x_cm - centre.x_cm, p.y_cm - centre.y_cm)
                - radius_cm)
                .abs(),
        }
    }
}

/// A board curve being cut into pieces.
#[derive(Debug, Clone, Copy)]
pub(super) struct PieceCut {
    pub(super) curve: Curve,
    /// Spot speed along the curve, mm/s (`None`: the axes' limit).
    pub(super) feed_mm_s: Option<f64>,
    pub(super) pieces: u32,
    /// Next piece end to queue (1..=pieces).
    pub(super) next: u32,
}

impl PieceCut {
    pub(super) fn point(&self, k: u32) -> BoardPoint {
        self.curve.at(f64::from(k) / f64::from(self.pieces))
    }
}

/// Distance from `p` to the segment `a`–`b`, cm.
fn distance_to_segment_cm(p: BoardPoint, a: BoardPoint, b: BoardPoint) -> f64 {
    let (dx, dy) = (b.x_cm - a.x_cm, b.y_cm - a.y_cm);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        clamp(
            ((p.x_cm - a.x_cm) * dx + (p.y_cm - a.y_cm) * dy) / len2,
            0.0,
            1.0,
        )
    } else {
        0.0
    };
    kinematics_core::numeric::hypot(p.x_cm - (a.x_cm + t * dx), p.y_cm - (a.y_cm + t * dy))
}
