//! The exact coupled gimbal model (SPEC §4.3), the default.
//!
//! Both servo axes pass through O. The laser origin is
//! `L = Rz(α)·(OL·sin β, 0, OL·cos β)` and the beam direction
//! `d = Rz(α)·(cos β, 0, −sin β)`; the spot is where `L + t·d` (t > 0) meets
//! the board plane. The beam is tangent to the circle of radius OL about O
//! in the vertical plane through the target, which gives the closed-form IK
//! `α = atan2(y, x)`, `h = √(x² + y²)`,
//! `β = π/2 − (atan2(z, h) + acos(OL / √(h² + z²)))`.

use super::joints::JointAngles;
use crate::error::Error;
use crate::frames::GlobalPoint;
use crate::numeric::{clamp, finite, trig};

/// Joint angles that put the spot on the global point `p` (cm).
///
/// `ol_cm` is the laser axis offset OL (cm, ≥ 0). Valid for any point in
/// front of the gimbal (`x_g > 0`) farther than OL from O; no servo limits
/// are applied here (see [`Gimbal::ik`](super::Gimbal::ik)).
///
/// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`] (OL < 0),
/// [`Error::BehindGimbal`] (`x_g <= 0`), [`Error::InsideOffsetCircle`]
/// (`√(x² + y² + z²) <= OL`).
pub fn ik(ol_cm: f64, p: GlobalPoint) -> Result<JointAngles, Error> {
    check_ol(ol_cm)?;
    p.check_finite()?;
    if p.x_cm <= 0.0 {
        return Err(Error::BehindGimbal);
    }
    let yaw_rad = libm::atan2(p.y_cm, p.x_cm);
    let h_cm = crate::numeric::hypot(p.x_cm, p.y_cm);
    let r_cm = crate::numeric::hypot(h_cm, p.z_cm);
    if r_cm <= ol_cm {
        return Err(Error::InsideOffsetCircle);
    }
    let theta_rad = libm::atan2(p.z_cm, h_cm);
    let lambda_rad = trig::acos(clamp(ol_cm / r_cm, 0.0, 1.0));
    let pitch_rad = core::f64::consts::FRAC_PI_2 - (theta_rad + lambda_rad);
    Ok(JointAngles {
        yaw_deg: yaw_rad.to_degrees(),
        pitch_deg: pitch_rad.to_degrees(),
    })
}

/// Laser origin `L` (cm) and unit beam direction `d` for joint angles `j`.
///
/// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`] (OL < 0).
pub fn beam(ol_cm: f64, j: JointAngles) -> Result<(GlobalPoint, [f64; 3]), Error> {
    check_ol(ol_cm)?;
    let (sa, ca) = trig::sin_cos(finite(j.yaw_deg, "yaw_deg")?.to_radians());
    let (sb, cb) = trig::sin_cos(finite(j.pitch_deg, "pitch_deg")?.to_radians());
    let origin = GlobalPoint {
        x_cm: ol_cm * sb * ca,
        y_cm: ol_cm * sb * sa,
        z_cm: ol_cm * cb,
    };
    Ok((origin, [cb * ca, cb * sa, -sb]))
}

/// Where the beam for joint angles `j` meets the plane `x_g = plane_x_cm`
/// (global point, cm).
///
/// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`] (OL < 0),
/// [`Error::BehindGimbal`] (`plane_x_cm <= 0`), [`Error::MissesBoard`]
/// (beam parallel to — within [`MIN_BEAM_X`] — or pointing away from the
/// plane).
pub fn fk(ol_cm: f64, plane_x_cm: f64, j: JointAngles) -> Result<GlobalPoint, Error> {
    if finite(plane_x_cm, "plane_x_cm")? <= 0.0 {
        return Err(Error::BehindGimbal);
    }
    let (l, [dx, dy, dz]) = beam(ol_cm, j)?;
    if dx <= MIN_BEAM_X {
        return Err(Error::MissesBoard);
    }
    let t_cm = (plane_x_cm - l.x_cm) / dx;
    if t_cm <= 0.0 || !t_cm.is_finite() {
        return Err(Error::MissesBoard);
    }
    let spot = GlobalPoint {
        x_cm: plane_x_cm,
        y_cm: l.y_cm + t_cm * dy,
        z_cm: l.z_cm + t_cm * dz,
    };
    spot.check_finite().map_err(|_| Error::MissesBoard)
}

/// Smallest x component of the unit beam direction that counts as hitting
/// the board: grazing beams (within 1e-9 rad of parallel, e.g. exactly 90°
/// in floating point) miss it rather than landing 10⁹ distances away.
pub const MIN_BEAM_X: f64 = 1e-9;

pub(super) fn check_ol(ol_cm: f64) -> Result<(), Error> {
    if finite(ol_cm, "ol_cm")? < 0.0 {
        Err(Error::InvalidConfig {
            what: "ol_cm must be >= 0",
        })
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const OL: f64 = 5.4;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn on_axis_at_laser_height_needs_no_rotation() {
        // With α = β = 0 the beam leaves L = (0, 0, OL) along +x: it hits the
        // board at height OL straight ahead.
        let j = ik(OL, GlobalPoint::new(25.0, 0.0, OL)).unwrap();
        assert!(close(j.yaw_deg, 0.0, 1e-12) && close(j.pitch_deg, 0.0, 1e-12));
        // At β = 0 the beam stays at height OL for any yaw: only α changes.
        let j = ik(OL, GlobalPoint::new(25.0, -10.0, OL)).unwrap();
        assert!(close(
            j.yaw_deg,
            libm::atan2(-10.0, 25.0).to_degrees(),
            1e-12
        ));
        assert!(close(j.pitch_deg, 0.0, 1e-12));
    }

    #[test]
    fn zero_offset_reduces_to_the_stepper_seed_formula() {
        // Stepper seed (OL = 0): yaw = atan(x/op), elevation = atan(y/√(x²+op²)),
        // with pitch β positive downward here.
        let (op, xb, yb) = (105.0, 20.0, -12.0);
        let j = ik(0.0, GlobalPoint::new(op, -xb, yb)).unwrap();
        assert!(close(j.yaw_deg, -libm::atan(xb / op).to_degrees(), 1e-12));
        let elev = libm::atan(yb / libm::sqrt(xb * xb + op * op)).to_degrees();
        assert!(close(j.pitch_deg, -elev, 1e-12));
    }

    #[test]
    fn straight_down_beam_hand_computed() {
        // β = 90°: L = (OL, 0, 0) (yaw 0), beam straight down — parallel to
        // the board plane, so no spot.
        let j = JointAngles {
            yaw_deg: 0.0,
            pitch_deg: 90.0,
        };
        assert_eq!(fk(OL, 25.0, j), Err(Error::MissesBoard));
        // β = 45°, α = 0: L = OL·(√½, 0, √½), d = (√½, 0, −√½): at x = 25 the
        // beam has dropped by (25 − OL·√½).
        let j = JointAngles {
            yaw_deg: 0.0,
            pitch_deg: 45.0,
        };
        let p = fk(OL, 25.0, j).unwrap();
        let h = core::f64::consts::FRAC_1_SQRT_2;
        assert!(close(p.z_cm, OL * h - (25.0 - OL * h), 1e-12));
        assert!(close(p.y_cm, 0.0, 1e-12));
    }

    #[test]
    fn errors_instead_of_nan() {
        assert_eq!(
            ik(OL, GlobalPoint::new(3.0, 0.0, 4.0)),
            Err(Error::InsideOffsetCircle)
        );
        assert_eq!(
            ik(OL, GlobalPoint::new(0.0, 10.0, 0.0)),
            Err(Error::BehindGimbal)
        );
        assert_eq!(
            ik(OL, GlobalPoint::new(-20.0, 0.0, 0.0)),
            Err(Error::BehindGimbal)
        );
        assert_eq!(
            ik(OL, GlobalPoint::new(25.0, f64::NAN, 0.0)),
            Err(Error::NonFinite { what: "y_g" })
        );
        assert_eq!(
            ik(-1.0, GlobalPoint::new(25.0, 0.0, 0.0)),
            Err(Error::InvalidConfig {
                what: "ol_cm must be >= 0"
            })
        );
        assert_eq!(
            ik(f64::INFINITY, GlobalPoint::new(25.0, 0.0, 0.0)),
            Err(Error::NonFinite { what: "ol_cm" })
        );
        let j = JointAngles {
            yaw_deg: 95.0,
            pitch_deg: 0.0,
        };
        assert_eq!(fk(OL, 25.0, j), Err(Error::MissesBoard));
        let j = JointAngles {
            yaw_deg: 0.0,
            pitch_deg: f64::NAN,
        };
        assert_eq!(fk(OL, 25.0, j), Err(Error::NonFinite { what: "pitch_deg" }));
        let j = JointAngles::default();
        assert_eq!(fk(OL, 0.0, j), Err(Error::BehindGimbal));
        // Pitched up so steeply the beam leaves "behind" L: the origin is past
        // the plane (t < 0) for a plane closer than OL·sin β.
        let j = JointAngles {
            yaw_deg: 0.0,
            pitch_deg: 80.0,
        };
        assert_eq!(fk(OL, 2.0, j), Err(Error::MissesBoard));
    }

    proptest! {
        // IK gives a beam through the target, checked directly (not via FK):
        // |L| = OL, L ⟂ d, and P − L is a positive multiple of d.
        #[test]
        fn ik_beam_passes_through_target(
            x in 0.1f64..300.0, y in -300.0f64..300.0, z in -300.0f64..300.0, ol in 0.0f64..20.0,
        ) {
            let p = GlobalPoint::new(x, y, z);
            prop_assume!(libm::sqrt(x * x + y * y + z * z) > ol * 1.001 + 1e-9);
            let j = ik(ol, p).unwrap();
            let (l, d) = beam(ol, j).unwrap();
            let lv = [l.x_cm, l.y_cm, l.z_cm];
            let norm_l = libm::sqrt(lv.iter().map(|c| c * c).sum::<f64>());
            prop_assert!(close(norm_l, ol, 1e-12));
            let dot: f64 = lv.iter().zip(d).map(|(a, b)| a * b).sum();
            prop_assert!(dot.abs() < 1e-12);
            let w = [x - l.x_cm, y - l.y_cm, z - l.z_cm];
            let along: f64 = w.iter().zip(d).map(|(a, b)| a * b).sum();
            prop_assert!(along > 0.0);
            let cross = [
                w[1] * d[2] - w[2] * d[1],
                w[2] * d[0] - w[0] * d[2],
                w[0] * d[1] - w[1] * d[0],
            ];
            let miss = libm::sqrt(cross.iter().map(|c| c * c).sum::<f64>());
            prop_assert!(miss < 1e-9, "beam misses target by {} cm", miss);
        }

        #[test]
        fn ik_of_fk_recovers_joint_angles(
            yaw in -60.0f64..60.0, pitch in -60.0f64..60.0, ol in 0.0f64..10.0, plane in 15.0f64..200.0,
        ) {
            let j = JointAngles { yaw_deg: yaw, pitch_deg: pitch };
            let p = fk(ol, plane, j).unwrap();
            let back = ik(ol, p).unwrap();
            prop_assert!(close(back.yaw_deg, yaw, 1e-9) && close(back.pitch_deg, pitch, 1e-9));
        }
    }
}
