//! Pinhole camera with radial distortion looking at the board plane
//! (board frame B, z = 0, z toward the viewer).

use nalgebra::{Matrix3, Vector3};

use crate::homography::Homography;

/// Interior orientation: focal lengths and principal point (px) and
/// radial distortion `x_d = x·(1 + k1·r² + k2·r⁴)` on normalised
/// coordinates (r² = x² + y²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Intrinsics {
    /// Focal length along x, px.
    pub fx: f64,
    /// Focal length along y, px.
    pub fy: f64,
    /// Principal point x, px.
    pub cx: f64,
    /// Principal point y, px.
    pub cy: f64,
    /// Radial distortion, r² term.
    pub k1: f64,
    /// Radial distortion, r⁴ term.
    pub k2: f64,
}

impl Intrinsics {
    /// Distorted pixel of the normalised (ideal) image point `n`.
    pub fn pixel_of_normalised(&self, n: [f64; 2]) -> [f64; 2] {
        let r2 = n[0] * n[0] + n[1] * n[1];
        let f = 1.0 + self.k1 * r2 + self.k2 * r2 * r2;
        [self.cx + self.fx * n[0] * f, self.cy + self.fy * n[1] * f]
    }

    /// Normalised (ideal) image point of distorted pixel `p` (fixed-point
    /// inversion of the distortion; exact to < 1e-9 for |k1·r²| < 0.2).
    pub fn normalised_of_pixel(&self, p: [f64; 2]) -> [f64; 2] {
        let d = [(p[0] - self.cx) / self.fx, (p[1] - self.cy) / self.fy];
        let mut n = d;
        if self.k1 == 0.0 && self.k2 == 0.0 {
            return n;
        }
        for _ in 0..30 {
            let r2 = n[0] * n[0] + n[1] * n[1];
            let f = 1.0 + self.k1 * r2 + self.k2 * r2 * r2;
            let next = [d[0] / f, d[1] / f];
            let step = (next[0] - n[0]).abs() + (next[1] - n[1]).abs();
            n = next;
            if step < 1e-13 {
                break;
            }
        }
        n
    }

    /// The distortion-free pixel (same focal length and principal point)
    /// of distorted pixel `p`: where a perfect lens would have imaged it.
    pub fn undistort_pixel(&self, p: [f64; 2]) -> [f64; 2] {
        let n = self.normalised_of_pixel(p);
        [self.cx + self.fx * n[0], self.cy + self.fy * n[1]]
    }

    /// The camera matrix K.
    pub fn k(&self) -> Matrix3<f64> {
        Matrix3::new(self.fx, 0.0, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0)
    }

    /// `k1` giving a radial displacement of `fraction` (0.005 = 0.5 %) at
    /// the corner of a `width × height` px image, for focal length `f` px.
    pub fn k1_for_corner_distortion(fraction: f64, width: f64, height: f64, f: f64) -> f64 {
        let r = (width / 2.0).hypot(height / 2.0) / f;
        fraction / (r * r)
    }
}

/// Exterior orientation: board → camera coordinates
/// `X_c = R·X_b + t` (camera x right, y down, z forward; mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Rotation board → camera.
    pub rotation: Matrix3<f64>,
    /// Board origin in camera coordinates, mm.
    pub translation: Vector3<f64>,
}

impl Pose {
    /// A camera at `eye` (board mm; z toward the viewer) looking at
    /// `target`, image "up" as close to board +y as possible.
    pub fn looking_at(eye: [f64; 3], target: [f64; 3]) -> Option<Pose> {
        let e = Vector3::from(eye);
        let f = (Vector3::from(target) - e).try_normalize(1e-12)?;
        let right = f.cross(&Vector3::y()).try_normalize(1e-12)?;
        let down = f.cross(&right);
        let rotation = Matrix3::from_rows(&[right.transpose(), down.transpose(), f.transpose()]);
        Some(Pose {
            rotation,
            translation: -(rotation * e),
        })
    }

    /// Camera centre in board coordinates, mm.
    pub fn centre(&self) -> Vector3<f64> {
        -(self.rotation.transpose() * self.translation)
    }

    /// Angle between the viewing direction to the board origin and the
    /// board normal, degrees.
    pub fn off_normal_deg(&self) -> f64 {
        let c = self.centre();
        (c.z / c.norm()).acos().to_degrees()
    }

    /// The homography board mm → normalised image coordinates.
    pub fn plane_homography(&self) -> Homography {
        let r = &self.rotation;
        Homography(Matrix3::from_columns(&[
            r.column(0).into_owned(),
            r.column(1).into_owned(),
            self.translation,
        ]))
    }
}

/// A camera: intrinsics, pose and sensor size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Interior orientation.
    pub intrinsics: Intrinsics,
    /// Exterior orientation.
    pub pose: Pose,
    /// Sensor width, px.
    pub width: usize,
    /// Sensor height, px.
    pub height: usize,
}

impl Camera {
    /// Pixel where board point `b` (mm) is imaged; `None` behind the camera.
    pub fn project(&self, b: [f64; 2]) -> Option<[f64; 2]> {
        let c = self.pose.rotation * Vector3::new(b[0], b[1], 0.0) + self.pose.translation;
        (c.z > 1e-9).then(|| self.intrinsics.pixel_of_normalised([c.x / c.z, c.y / c.z]))
    }

    /// Board point (mm) imaged at pixel `p`; `None` if that ray misses the board.
    pub fn board_point(&self, p: [f64; 2]) -> Option<[f64; 2]> {
        let n = self.intrinsics.normalised_of_pixel(p);
        self.pose.plane_homography().inverse()?.apply(n)
    }

    /// The reference set-up of the acceptance figures (issue 22): 1280 × 720,
    /// 60° horizontal field of view, camera 24° off the board normal (below
    /// and to the side of the laser, so it never blocks the beam), 480 mm
    /// from the board centre, radial distortion `k1`.
    pub fn reference(k1: f64) -> Camera {
        let (width, height) = (1280, 720);
        let f = 640.0 / (30f64).to_radians().tan();
        let eye = [-90.0, -170.0, 440.0];
        let pose = Pose::looking_at(eye, [0.0, -8.0, 0.0]).unwrap_or(Pose {
            rotation: Matrix3::identity(),
            translation: Vector3::new(0.0, 0.0, 480.0),
        });
        Camera {
            intrinsics: Intrinsics {
                fx: f,
                fy: f,
                cx: 639.5,
                cy: 359.5,
                k1,
                k2: 0.0,
            },
            pose,
            width,
            height,
        }
    }
}

/// Camera positions (board mm) around the reference camera from which a
/// user views the target for the intrinsics (equivalently: holds the
/// printed board at different tilts), each looking at the board origin.
pub const INTRINSICS_VIEW_EYES: [[f64; 3]; 5] = [
    [-90.0, -170.0, 440.0],
    [120.0, -140.0, 450.0],
    [-150.0, 90.0, 430.0],
    [40.0, 160.0, 460.0],
    [0.0, -30.0, 520.0],
];

impl Camera {
    /// This camera moved to `eye` (board mm), looking at the board origin.
    pub fn from_eye(&self, eye: [f64; 3]) -> Option<Camera> {
        Some(Camera {
            pose: Pose::looking_at(eye, [0.0, 0.0, 0.0])?,
            ..*self
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn project_and_back_are_inverse_with_distortion() {
        let k1 = Intrinsics::k1_for_corner_distortion(0.005, 1280.0, 720.0, 1108.0);
        let cam = Camera::reference(k1);
        assert!(
            cam.pose.off_normal_deg() >= 20.0,
            "{}",
            cam.pose.off_normal_deg()
        );
        for b in [[0.0, 0.0], [120.0, 80.0], [-150.0, -110.0], [140.0, -100.0]] {
            let p = cam.project(b).unwrap();
            assert!(
                p[0] > 0.0 && p[0] < 1279.0 && p[1] > 0.0 && p[1] < 719.0,
                "{b:?} -> {p:?}"
            );
            let back = cam.board_point(p).unwrap();
            assert!((back[0] - b[0]).abs() < 1e-6 && (back[1] - b[1]).abs() < 1e-6);
        }
        // Board +x appears to the right, board +y up.
        let (o, x, y) = (
            cam.project([0.0, 0.0]).unwrap(),
            cam.project([10.0, 0.0]).unwrap(),
            cam.project([0.0, 10.0]).unwrap(),
        );
        assert!(x[0] > o[0] && y[1] < o[1]);
    }

    #[test]
    fn corner_distortion_is_the_asked_fraction() {
        let i = Intrinsics {
            fx: 1000.0,
            fy: 1000.0,
            cx: 640.0,
            cy: 360.0,
            k1: Intrinsics::k1_for_corner_distortion(0.005, 1280.0, 720.0, 1000.0),
            k2: 0.0,
        };
        let ideal = [0.64, 0.36];
        let p = i.pixel_of_normalised(ideal);
        let r_ideal = 640f64.hypot(360.0);
        let r = (p[0] - 640.0).hypot(p[1] - 360.0);
        assert!((r / r_ideal - 1.005).abs() < 1e-12);
        let u = i.undistort_pixel(p);
        assert!((u[0] - 1280.0).abs() < 1e-8 && (u[1] - 720.0).abs() < 1e-8);
    }
}
