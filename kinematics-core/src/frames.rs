//! Board and global frames (SPEC §4.1) with the seed's board offsets and a
//! board pose (mounting error).
//!
//! Global frame G: origin O at the gimbal's rotation centre, x toward the
//! board, z up (so y points left as seen from the gimbal). Board frame B:
//! origin Q on G's x axis at distance OQ, board x = G's −y (right as seen
//! from the gimbal), board y = G's z (up). With no pose error,
//! `x_g = OQ, y_g = −x_b, z_g = y_b`.

use crate::error::Error;
use crate::numeric::{finite, trig};
use crate::real::Real;

/// Centimetres per millimetre.
const CM_PER_MM: f64 = 0.1;
/// Millimetres per centimetre.
const MM_PER_CM: f64 = 10.0;

/// A point on the board, board frame, centimetres.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BoardPoint {
    /// Board x (right as seen from the gimbal), cm.
    pub x_cm: f64,
    /// Board y (up), cm.
    pub y_cm: f64,
}

impl BoardPoint {
    /// A board point from its coordinates in cm.
    pub const fn new(x_cm: f64, y_cm: f64) -> Self {
        Self { x_cm, y_cm }
    }

    /// The same point in millimetres.
    pub fn to_mm(self) -> PointMm {
        PointMm {
            x_mm: self.x_cm * MM_PER_CM,
            y_mm: self.y_cm * MM_PER_CM,
        }
    }

    /// `Err(NonFinite)` unless both coordinates are finite.
    pub fn check_finite(self) -> Result<Self, Error> {
        finite(self.x_cm, "x_cm")?;
        finite(self.y_cm, "y_cm")?;
        Ok(self)
    }
}

/// A point in the board plane in millimetres (board axes), used by the
/// galvo kinematics (generic float, `f32` per sample) and the error model.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PointMm<F = f64> {
    /// Board x, mm.
    pub x_mm: F,
    /// Board y, mm.
    pub y_mm: F,
}

impl<F: Real> PointMm<F> {
    /// A point from its coordinates in mm.
    pub const fn new(x_mm: F, y_mm: F) -> Self {
        Self { x_mm, y_mm }
    }

    /// `Err(NonFinite)` unless both coordinates are finite.
    pub fn check_finite(self) -> Result<Self, Error> {
        if !self.x_mm.is_finite() {
            return Err(Error::NonFinite { what: "x_mm" });
        }
        if !self.y_mm.is_finite() {
            return Err(Error::NonFinite { what: "y_mm" });
        }
        Ok(self)
    }
}

impl PointMm<f64> {
    /// The same point in centimetres.
    pub fn to_cm(self) -> BoardPoint {
        BoardPoint {
            x_cm: self.x_mm * CM_PER_MM,
            y_cm: self.y_mm * CM_PER_MM,
        }
    }
}

/// A point in the global frame G, centimetres.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GlobalPoint {
    /// Global x (toward the board), cm.
    pub x_cm: f64,
    /// Global y (left as seen from the gimbal), cm.
    pub y_cm: f64,
    /// Global z (up), cm.
    pub z_cm: f64,
}

impl GlobalPoint {
    /// A global point from its coordinates in cm.
    pub const fn new(x_cm: f64, y_cm: f64, z_cm: f64) -> Self {
        Self { x_cm, y_cm, z_cm }
    }

    /// `Err(NonFinite)` unless all coordinates are finite.
    pub fn check_finite(self) -> Result<Self, Error> {
        finite(self.x_cm, "x_g")?;
        finite(self.y_cm, "y_g")?;
        finite(self.z_cm, "z_g")?;
        Ok(self)
    }
}

/// Mounting error of the board relative to its nominal place (the seed's
/// "translation error" and "rotation error"): a translation in the global
/// frame and a rotation about the global x axis (the board normal), applied
/// about the board origin Q.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BoardPose {
    /// Translation along global x (adds to OQ), cm.
    pub dx_cm: f64,
    /// Translation along global y, cm.
    pub dy_cm: f64,
    /// Translation along global z, cm.
    pub dz_cm: f64,
    /// Rotation of the board about global +x (right-handed: board axes turn
    /// from global y toward z, clockwise as seen from the gimbal), degrees.
    pub roll_deg: f64,
}

/// Where the board is: distance OQ, the seed's board offsets and the pose.
///
/// A commanded board point `p` is aimed at `p + (x_offset_cm, y_offset_cm)`
/// (the seed's `XB_OFFSET`/`YB_OFFSET`, added before the transform), in a
/// board frame placed by `oq_cm` and `pose`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoardFrame {
    /// Distance OQ from the gimbal centre to the board origin, cm (> 0).
    pub oq_cm: f64,
    /// Seed `XB_OFFSET`: added to every commanded board x, cm.
    pub x_offset_cm: f64,
    /// Seed `YB_OFFSET`: added to every commanded board y, cm.
    pub y_offset_cm: f64,
    /// Board mounting error.
    pub pose: BoardPose,
}

impl Default for BoardFrame {
    /// SPEC defaults: OQ = 25 cm, no offsets, no pose error.
    fn default() -> Self {
        Self {
            oq_cm: DEFAULT_OQ_CM,
            x_offset_cm: 0.0,
            y_offset_cm: 0.0,
            pose: BoardPose::default(),
        }
    }
}

/// SPEC default distance OQ, cm.
pub const DEFAULT_OQ_CM: f64 = 25.0;

impl BoardFrame {
    /// Checks every field is finite and the board plane is in front of the
    /// gimbal (`oq_cm + pose.dx_cm > 0`).
    ///
    /// Errors: [`Error::NonFinite`], [`Error::BehindGimbal`].
    pub fn validate(&self) -> Result<(), Error> {
        finite(self.oq_cm, "oq_cm")?;
        finite(self.x_offset_cm, "x_offset_cm")?;
        finite(self.y_offset_cm, "y_offset_cm")?;
        finite(self.pose.dx_cm, "pose.dx_cm")?;
        finite(self.pose.dy_cm, "pose.dy_cm")?;
        finite(self.pose.dz_cm, "pose.dz_cm")?;
        finite(self.pose.roll_deg, "pose.roll_deg")?;
        if self.plane_x() > 0.0 {
            Ok(())
        } else {
            Err(Error::BehindGimbal)
        }
    }

    /// Global x of the board plane (`oq_cm + pose.dx_cm`), cm. The roll is
    /// about global x, so the board stays the plane `x_g = plane_x_cm`.
    ///
    /// Errors: as [`validate`](Self::validate).
    pub fn plane_x_cm(&self) -> Result<f64, Error> {
        self.validate()?;
        Ok(self.plane_x())
    }

    /// [`plane_x_cm`](Self::plane_x_cm) without the checks.
    fn plane_x(&self) -> f64 {
        self.oq_cm + self.pose.dx_cm
    }

    fn roll_sin_cos(&self) -> (f64, f64) {
        let roll_rad = self.pose.roll_deg.to_radians();
        (trig::sin(roll_rad), trig::cos(roll_rad))
    }

    /// Board point (cm, before the offsets are added) → global point (cm).
    ///
    /// Errors: [`Error::NonFinite`], [`Error::BehindGimbal`] (invalid frame).
    pub fn board_to_global(&self, p: BoardPoint) -> Result<GlobalPoint, Error> {
        self.validate()?;
        p.check_finite()?;
        let u = p.x_cm + self.x_offset_cm;
        let v = p.y_cm + self.y_offset_cm;
        let (s, c) = self.roll_sin_cos();
        // Rx(roll) · (0, −u, v) + origin.
        Ok(GlobalPoint {
            x_cm: self.plane_x(),
            y_cm: self.pose.dy_cm - c * u - s * v,
            z_cm: self.pose.dz_cm - s * u + c * v,
        })
    }

    /// Global point (cm) → board point (cm, with the offsets removed, so it
    /// inverts [`board_to_global`](Self::board_to_global)). The point is
    /// projected along global x onto the board plane: its distance from the
    /// plane is ignored.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::BehindGimbal`] (invalid frame).
    pub fn global_to_board(&self, g: GlobalPoint) -> Result<BoardPoint, Error> {
        self.validate()?;
        g.check_finite()?;
        let (s, c) = self.roll_sin_cos();
        let gy = g.y_cm - self.pose.dy_cm;
        let gz = g.z_cm - self.pose.dz_cm;
        // Rx(roll)ᵀ · (g − origin) = (·, −u, v).
        let u = -(c * gy + s * gz);
        let v = -s * gy + c * gz;
        Ok(BoardPoint {
            x_cm: u - self.x_offset_cm,
            y_cm: v - self.y_offset_cm,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn nominal_frame_is_the_seed_transform() {
        let f = BoardFrame::default();
        let g = f.board_to_global(BoardPoint::new(3.0, -2.0)).unwrap();
        // Seed: xg = OQ, yg = −xb, zg = yb.
        assert_eq!(g, GlobalPoint::new(25.0, -3.0, -2.0));
        let b = f.global_to_board(GlobalPoint::new(25.0, 7.0, 1.5)).unwrap();
        assert_eq!(b, BoardPoint::new(-7.0, 1.5));
    }

    #[test]
    fn offsets_are_added_before_the_transform() {
        let f = BoardFrame {
            x_offset_cm: 1.0,
            y_offset_cm: -0.5,
            ..BoardFrame::default()
        };
        let g = f.board_to_global(BoardPoint::new(0.0, 0.0)).unwrap();
        assert_eq!(g, GlobalPoint::new(25.0, -1.0, -0.5));
    }

    #[test]
    fn roll_quarter_turn_maps_board_x_to_global_minus_z() {
        // Rotating the board +90° about +x: its x axis (global −y) turns to
        // global −z, its y axis (global +z) to global −y.
        let f = BoardFrame {
            pose: BoardPose {
                roll_deg: 90.0,
                ..BoardPose::default()
            },
            ..BoardFrame::default()
        };
        let gx = f.board_to_global(BoardPoint::new(1.0, 0.0)).unwrap();
        assert!(gx.y_cm.abs() < 1e-15 && (gx.z_cm + 1.0).abs() < 1e-15);
        let gy = f.board_to_global(BoardPoint::new(0.0, 1.0)).unwrap();
        assert!((gy.y_cm + 1.0).abs() < 1e-15 && gy.z_cm.abs() < 1e-15);
    }

    #[test]
    fn translation_moves_the_origin() {
        let f = BoardFrame {
            pose: BoardPose {
                dx_cm: 2.0,
                dy_cm: 0.5,
                dz_cm: -1.0,
                roll_deg: 0.0,
            },
            ..BoardFrame::default()
        };
        let g = f.board_to_global(BoardPoint::new(0.0, 0.0)).unwrap();
        assert_eq!(g, GlobalPoint::new(27.0, 0.5, -1.0));
        assert_eq!(f.plane_x_cm(), Ok(27.0));
    }

    #[test]
    fn invalid_frames_and_points_are_errors() {
        let f = BoardFrame {
            oq_cm: f64::NAN,
            ..BoardFrame::default()
        };
        assert_eq!(
            f.board_to_global(BoardPoint::default()),
            Err(Error::NonFinite { what: "oq_cm" })
        );
        let behind = BoardFrame {
            oq_cm: 1.0,
            pose: BoardPose {
                dx_cm: -1.0,
                ..BoardPose::default()
            },
            ..BoardFrame::default()
        };
        assert_eq!(
            behind.board_to_global(BoardPoint::default()),
            Err(Error::BehindGimbal)
        );
        let f = BoardFrame::default();
        assert_eq!(
            f.board_to_global(BoardPoint::new(f64::INFINITY, 0.0)),
            Err(Error::NonFinite { what: "x_cm" })
        );
        assert_eq!(
            f.global_to_board(GlobalPoint::new(25.0, 0.0, f64::NAN)),
            Err(Error::NonFinite { what: "z_g" })
        );
    }

    #[test]
    fn mm_and_cm_convert() {
        let p = BoardPoint::new(1.5, -2.0).to_mm();
        assert_eq!(p, PointMm::new(15.0, -20.0));
        assert_eq!(p.to_cm(), BoardPoint::new(1.5, -2.0));
        assert!(PointMm::new(f32::NAN, 0.0).check_finite().is_err());
    }

    proptest! {
        #[test]
        fn board_global_board_is_identity(
            x in -50.0f64..50.0, y in -50.0f64..50.0,
            oq in 5.0f64..500.0, dx in -4.0f64..4.0, dy in -5.0f64..5.0, dz in -5.0f64..5.0,
            roll in -180.0f64..180.0, xo in -10.0f64..10.0, yo in -10.0f64..10.0,
        ) {
            let f = BoardFrame {
                oq_cm: oq, x_offset_cm: xo, y_offset_cm: yo,
                pose: BoardPose { dx_cm: dx, dy_cm: dy, dz_cm: dz, roll_deg: roll },
            };
            let g = f.board_to_global(BoardPoint::new(x, y)).unwrap();
            prop_assert_eq!(g.x_cm, oq + dx);
            // Rigid motion: the distance from the board origin is preserved.
            let r_board = crate::numeric::hypot(x + xo, y + yo);
            let r_global = crate::numeric::hypot(g.y_cm - dy, g.z_cm - dz);
            prop_assert!((r_board - r_global).abs() < 1e-12 * (1.0 + r_board));
            let b = f.global_to_board(g).unwrap();
            prop_assert!((b.x_cm - x).abs() < 1e-12 && (b.y_cm - y).abs() < 1e-12);
        }
    }
}
