//! The simulated world's geometry: where the laser spot lands for the
//! simulated servos' actual angles. This is the "truth" the simulator
//! draws and the tests measure against, computed with the exact coupled
//! forward kinematics of `kinematics-core` (SPEC §4.3), independent of the
//! model the firmware aims with.

use kinematics_core::{Galvo, Gimbal, GimbalModel, JointAngles};

/// The physical gimbal: which bus ids drive which joint, and its true
/// geometry and servo mapping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysicalGimbal {
    /// Bus id of the yaw servo.
    pub yaw_id: u8,
    /// Bus id of the pitch servo.
    pub pitch_id: u8,
    /// True geometry (exact model), servo mapping and board pose.
    pub gimbal: Gimbal,
}

impl Default for PhysicalGimbal {
    /// The SPEC default build: ids 0 (yaw) and 1 (pitch), OQ 25 cm,
    /// OL 5.4 cm, servos mounted with direction +1, scale 1, zero 0.
    fn default() -> Self {
        Self {
            yaw_id: 0,
            pitch_id: 1,
            gimbal: Gimbal::with_model(GimbalModel::Exact),
        }
    }
}

impl PhysicalGimbal {
    /// Board point (cm) the spot lands on with the yaw servo at
    /// `yaw_servo_deg` and the pitch servo at `pitch_servo_deg` (servo
    /// angles, deg); `None` when the beam misses the board.
    pub fn spot_cm(&self, yaw_servo_deg: f64, pitch_servo_deg: f64) -> Option<(f64, f64)> {
        let geometry = &self.gimbal.geometry;
        let joints = JointAngles {
            yaw_deg: geometry.yaw.servo_deg_to_joint(yaw_servo_deg).ok()?,
            pitch_deg: geometry.pitch.servo_deg_to_joint(pitch_servo_deg).ok()?,
        };
        let p = self.gimbal.fk(joints).ok()?;
        Some((p.x_cm, p.y_cm))
    }
}

/// The physical galvo: the SPEC default geometry and DAC span. The
/// mirrors follow the DAC ideally (each sample's angle is reached within
/// the sample: the planner's trajectories respect the drive's limits).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PhysicalGalvo {
    /// True geometry and DAC mapping.
    pub galvo: Galvo<f64>,
}

impl PhysicalGalvo {
    /// Board point (cm) of the spot for DAC codes `x_code`, `y_code`.
    pub fn spot_cm(&self, x_code: u16, y_code: u16) -> Option<(f64, f64)> {
        let p = self.galvo.codes_to_board(x_code, y_code).ok()?;
        Some((p.x_mm / 10.0, p.y_mm / 10.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinematics_core::BoardPoint;

    #[test]
    fn spot_inverts_the_firmware_aim_chain() {
        let g = PhysicalGimbal::default();
        for (x, y) in [(0.0, 0.0), (11.496, 7.664), (-11.496, -7.664), (3.0, -2.0)] {
            let wire = g.gimbal.ik_wire(BoardPoint::new(x, y)).unwrap();
            let (sx, sy) = g
                .spot_cm(f64::from(wire.yaw) / 10.0, f64::from(wire.pitch) / 10.0)
                .unwrap();
            // 0.05° wire rounding ≈ 0.3 mm at this range.
            assert!(
                (sx - x).abs() < 0.04 && (sy - y).abs() < 0.04,
                "({sx}, {sy})"
            );
        }
    }

    #[test]
    fn a_beam_away_from_the_board_has_no_spot() {
        let g = PhysicalGimbal::default();
        assert_eq!(g.spot_cm(120.0, 0.0), None);
        assert_eq!(g.spot_cm(f64::NAN, 0.0), None);
    }
}
