//! Cutting a board line or arc into pieces for the stepper: how many
//! pieces (a power of two) keep the spot within [`LINE_TOLERANCE_MM`] of
//! it (the curve and the pieces' ends are in `curve.rs`).

use kinematics_core::gimbal::JointAngles;

use super::super::link::messages::StepperRefusal;
use super::curve::{Curve, PieceCut};
use super::{LINE_TOLERANCE_MM, MAX_PIECES, StepperMotion};

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
        Ok(crate::domain::units::mm_from_cm(curve.distance_cm(spot)))
    }
}
