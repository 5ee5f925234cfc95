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
    /// the soft limits.
    pub(super) fn pieces_for(&self, curve: Curve) -> Result<u32, StepperRefusal> {
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
            let mid = JointAngles {
                yaw_deg: 0.5 * (a.yaw_deg + b.yaw_deg),
                pitch_deg: 0.5 * (a.pitch_deg + b.pitch_deg),
            };
            let spot = self
                .config
                .gimbal
                .fk(mid)
                .map_err(|_| StepperRefusal::Unreachable)?;
            worst = worst.max(10.0 * cut.curve.distance_cm(spot));
            a = b;
        }
        Ok(worst)
    }
}
