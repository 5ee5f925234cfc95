//! The seed's gimbal model (SPEC §4.2), kept for comparison.
//!
//! It solves yaw and pitch independently: `α = atan2(y, x)` and pitch from
//! the tangent construction in the x–z plane as if the target were straight
//! ahead (`θ = atan2(z, x)`, `λ = acos(OL / √(x² + z²))`,
//! `β = π/2 − (θ + λ)`). Its FK (`y = x·tan α`,
//! `z = OL·cos β − (x − OL·sin β)·tan β`) is its exact inverse, but the
//! pair ignores how yaw lengthens the path to the board, so off-centre
//! spots miss (evaluated with the exact model): by 13.9 mm at the default
//! grid's bottom corners, 2.3 mm at its top corners, and not at all at the
//! laser's height (board y = OL, where the beam is level) or on the
//! vertical axis. `cargo xtask kin grid-error` prints the whole table.

use super::exact::{MIN_BEAM_X, check_ol};
use super::joints::JointAngles;
use crate::error::Error;
use crate::frames::GlobalPoint;
use crate::numeric::{clamp, finite, trig};

/// Seed IK: joint angles for the global point `p` (cm), `ol_cm` = OL (cm).
///
/// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`] (OL < 0),
/// [`Error::BehindGimbal`] (`x_g <= 0`), [`Error::InsideOffsetCircle`]
/// (`√(x² + z²) <= OL`).
pub fn ik(ol_cm: f64, p: GlobalPoint) -> Result<JointAngles, Error> {
    check_ol(ol_cm)?;
    p.check_finite()?;
    if p.x_cm <= 0.0 {
        return Err(Error::BehindGimbal);
    }
    let yaw_rad = libm::atan2(p.y_cm, p.x_cm);
    let theta_rad = libm::atan2(p.z_cm, p.x_cm);
    let op3_cm = crate::numeric::hypot(p.x_cm, p.z_cm);
    if op3_cm <= ol_cm {
        return Err(Error::InsideOffsetCircle);
    }
    let lambda_rad = trig::acos(clamp(ol_cm / op3_cm, 0.0, 1.0));
    let pitch_rad = core::f64::consts::FRAC_PI_2 - (theta_rad + lambda_rad);
    Ok(JointAngles {
        yaw_deg: yaw_rad.to_degrees(),
        pitch_deg: pitch_rad.to_degrees(),
    })
}

/// Seed FK: the spot (global point, cm) on the plane `x_g = plane_x_cm` for
/// joint angles `j`.
///
/// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`] (OL < 0),
/// [`Error::BehindGimbal`] (`plane_x_cm <= 0`), [`Error::MissesBoard`]
/// (|α| or |β| within [`MIN_BEAM_X`] of 90° or beyond, or the plane is
/// behind the laser origin).
pub fn fk(ol_cm: f64, plane_x_cm: f64, j: JointAngles) -> Result<GlobalPoint, Error> {
    check_ol(ol_cm)?;
    let x_cm = finite(plane_x_cm, "plane_x_cm")?;
    if x_cm <= 0.0 {
        return Err(Error::BehindGimbal);
    }
    let (sa, ca) = trig::sin_cos(finite(j.yaw_deg, "yaw_deg")?.to_radians());
    let (sb, cb) = trig::sin_cos(finite(j.pitch_deg, "pitch_deg")?.to_radians());
    if ca <= MIN_BEAM_X || cb <= MIN_BEAM_X || x_cm - ol_cm * sb <= 0.0 {
        return Err(Error::MissesBoard);
    }
    let spot = GlobalPoint {
        x_cm,
        y_cm: x_cm * sa / ca,
        z_cm: ol_cm * cb - (x_cm - ol_cm * sb) * sb / cb,
    };
    spot.check_finite().map_err(|_| Error::MissesBoard)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gimbal::exact;
    use proptest::prelude::*;

    #[test]
    fn matches_the_seed_c_code_by_hand() {
        // IK_GimbalLaser(25, -5, 3) with OL = 5.4, evaluated step by step.
        let (xg, yg, zg, ol) = (25.0f64, -5.0f64, 3.0f64, 5.4f64);
        let alpha = libm::atan2(yg, xg);
        let theta = libm::atan2(zg, xg);
        let op3 = libm::sqrt(xg * xg + zg * zg);
        let beta = core::f64::consts::FRAC_PI_2 - (theta + libm::acos(ol / op3));
        let j = ik(ol, GlobalPoint::new(xg, yg, zg)).unwrap();
        assert!((j.yaw_deg - alpha.to_degrees()).abs() < 1e-12);
        assert!((j.pitch_deg - beta.to_degrees()).abs() < 1e-12);
    }

    #[test]
    fn equals_the_exact_model_on_the_vertical_axis() {
        // With y = 0 there is no yaw, h = x, and both models are the same.
        for z in [-10.0, -3.0, 0.0, 4.0, 12.0] {
            let p = GlobalPoint::new(25.0, 0.0, z);
            let s = ik(5.4, p).unwrap();
            let e = exact::ik(5.4, p).unwrap();
            assert!((s.pitch_deg - e.pitch_deg).abs() < 1e-12);
            assert_eq!(s.yaw_deg, 0.0);
        }
    }

    #[test]
    fn differs_from_the_exact_model_off_axis() {
        // Off-axis the seed solves pitch for distance x instead of h > x, so
        // its pitch is steeper than needed for a target below laser height.
        let p = GlobalPoint::new(25.0, 11.5, -7.7);
        let s = ik(5.4, p).unwrap();
        let e = exact::ik(5.4, p).unwrap();
        assert!(s.pitch_deg > e.pitch_deg + 0.1);
    }

    #[test]
    fn errors_instead_of_nan() {
        assert_eq!(
            ik(5.4, GlobalPoint::new(4.0, 30.0, 2.0)),
            Err(Error::InsideOffsetCircle)
        );
        assert_eq!(
            ik(5.4, GlobalPoint::new(-1.0, 0.0, 0.0)),
            Err(Error::BehindGimbal)
        );
        assert_eq!(
            ik(5.4, GlobalPoint::new(25.0, 0.0, f64::INFINITY)),
            Err(Error::NonFinite { what: "z_g" })
        );
        let j = JointAngles {
            yaw_deg: 90.0,
            pitch_deg: 0.0,
        };
        assert_eq!(fk(5.4, 25.0, j), Err(Error::MissesBoard));
        let j = JointAngles {
            yaw_deg: 0.0,
            pitch_deg: -90.0,
        };
        assert_eq!(fk(5.4, 25.0, j), Err(Error::MissesBoard));
        assert_eq!(
            fk(5.4, f64::NAN, JointAngles::default()),
            Err(Error::NonFinite { what: "plane_x_cm" })
        );
        assert_eq!(
            fk(5.4, -3.0, JointAngles::default()),
            Err(Error::BehindGimbal)
        );
    }

    proptest! {
        #[test]
        fn fk_of_ik_is_identity(
            y in -40.0f64..40.0, z in -40.0f64..40.0, x in 10.0f64..200.0, ol in 0.0f64..9.0,
        ) {
            let p = GlobalPoint::new(x, y, z);
            let j = ik(ol, p).unwrap();
            let back = fk(ol, x, j).unwrap();
            prop_assert!((back.y_cm - y).abs() < 1e-9 && (back.z_cm - z).abs() < 1e-9);
        }
    }
}
