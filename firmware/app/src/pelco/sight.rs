//! PELCO pan/tilt angles of a board point: the line of sight from the
//! aiming centre O (distance OQ from the board, Q the board origin).
//!
//! pan = atan2(x, OQ), tilt = atan2(y, √(x² + OQ²)); back, x = OQ·tan(pan),
//! y = √(x² + OQ²)·tan(tilt). The same angles whichever actuator aims, so
//! a preset or an absolute position means the same spot on every one.

use kinematics_core::numeric::hypot;
use kinematics_core::numeric::trig::sin_cos;

use crate::domain::PointCm;

/// Largest |pan| and |tilt| a PELCO command may ask, deg (beyond it the
/// board point runs off to infinity).
pub const MAX_ANGLE_DEG: f64 = 80.0;

/// `(pan, tilt)` of board point `p`, deg, for a centre `oq_cm` from the
/// board.
pub fn angles_deg(p: PointCm, oq_cm: f64) -> [f64; 2] {
    let pan = libm::atan2(p.x_cm, oq_cm);
    let tilt = libm::atan2(p.y_cm, hypot(p.x_cm, oq_cm));
    [pan.to_degrees(), tilt.to_degrees()]
}

/// The board point at `(pan, tilt)` deg (each clamped to
/// ±[`MAX_ANGLE_DEG`]), cm.
pub fn point(angles_deg: [f64; 2], oq_cm: f64) -> PointCm {
    let [pan, tilt] = angles_deg.map(|a| a.clamp(-MAX_ANGLE_DEG, MAX_ANGLE_DEG).to_radians());
    // tan as sin / cos: the firmware's own trig (libm's tan is 4.5 KB of
    // flash more); |angle| ≤ 80° keeps cos away from 0.
    let tan = |a: f64| {
        let (sin, cos) = sin_cos(a);
        sin / cos
    };
    let x = oq_cm * tan(pan);
    let y = hypot(x, oq_cm) * tan(tilt);
    PointCm::new(x, y)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    proptest! {
        #[test]
        fn point_of_angles_inverts(pan in -79.0f64..79.0, tilt in -79.0f64..79.0, oq in 5.0f64..500.0) {
            let [p, t] = angles_deg(point([pan, tilt], oq), oq);
            prop_assert!((p - pan).abs() < 1e-9 && (t - tilt).abs() < 1e-9);
        }
    }

    #[test]
    fn straight_ahead_is_the_origin() {
        assert_eq!(angles_deg(PointCm::new(0.0, 0.0), 100.0), [0.0, 0.0]);
        let p = point([45.0, 0.0], 100.0);
        assert!((p.x_cm - 100.0).abs() < 1e-9 && p.y_cm.abs() < 1e-9);
    }
}
