//! Cutting a board line or arc into pieces for the stepper: the curve,
//! how many pieces (a power of two) keep the spot within
//! [`LINE_TOLERANCE_MM`] of it, and the pieces' ends.

use kinematics_core::frames::BoardPoint;
use kinematics_core::gimbal::JointAngles;
use kinematics_core::numeric::clamp;
use kinematics_core::path::{Segment as BoardSegment, Shape};

use super::super::{MoveShape, StepperRefusal};
use super::{LINE_TOLERANCE_MM, MAX_PIECES, StepperMotion};

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
    fn at(&self, t: f64) -> BoardPoint {
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
    fn distance_cm(&self, p: BoardPoint) -> f64 {
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

impl StepperMotion {
    /// The fewest pieces (a power of two) whose joint-space midpoints lie
    /// within [`LINE_TOLERANCE_MM`] of the curve; every piece end within
    /// the soft limits. Counted in single precision when that is sure
    /// (`fast.rs`), else through the f64 IK and FK of every piece.
    pub(super) fn pieces_for(&self, curve: Curve) -> Result<u32, StepperRefusal> {
        let exact_mm = |k: u32, pieces: u32| {
            let cut = PieceCut {
                curve,
                feed_mm_s: None,
                pieces,
                next: 1,
            };
            let a = self.joints_at(cut.point(k - 1)).ok()?;
            let b = self.joints_at(cut.point(k)).ok()?;
            self.mid_deviation_mm(&curve, a, b).ok()
        };
        let fast = self.joints32.and_then(|j| {
            j.pieces(
                curve.shape(),
                curve.fewest_pieces(),
                LINE_TOLERANCE_MM,
                MAX_PIECES,
                &exact_mm,
            )
        });
        if let Some(pieces) = fast {
            return Ok(pieces);
        }
        self.pieces_exactly(curve)
    }

    /// [`Self::pieces_for`] through the f64 IK and FK of every piece.
    #[inline(never)]
    pub(super) fn pieces_exactly(&self, curve: Curve) -> Result<u32, StepperRefusal> {
        let mut pieces = curve.fewest_pieces();
        loop {
            let cut = PieceCut {
                curve,
                feed_mm_s: None,
                pieces,
                next: 1,
            };
            if self.max_deviation_mm(&cut)? <= LINE_TOLERANCE_MM || pieces >= MAX_PIECES {
                return Ok(pieces);
            }
            pieces *= 2;
        }
    }

    /// Largest distance of a piece's joint-space midpoint from the curve,
    /// mm.
    fn max_deviation_mm(&self, cut: &PieceCut) -> Result<f64, StepperRefusal> {
        let mut worst = 0.0_f64;
        let mut a = self.joints_at(cut.point(0))?;
        for k in 1..=cut.pieces {
            let b = self.joints_at(cut.point(k))?;
            self.config.steps_of(b)?;
            worst = worst.max(self.mid_deviation_mm(&cut.curve, a, b)?);
            a = b;
        }
        Ok(worst)
    }

    /// Distance of the joint-space midpoint of ends `a` and `b` from
    /// `curve`, mm.
    fn mid_deviation_mm(
        &self,
        curve: &Curve,
        a: JointAngles,
        b: JointAngles,
    ) -> Result<f64, StepperRefusal> {
        let mid = JointAngles {
            yaw_deg: 0.5 * (a.yaw_deg + b.yaw_deg),
            pitch_deg: 0.5 * (a.pitch_deg + b.pitch_deg),
        };
        let spot = self
            .config
            .gimbal
            .fk(mid)
            .map_err(|_| StepperRefusal::Unreachable)?;
        Ok(10.0 * curve.distance_cm(spot))
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
