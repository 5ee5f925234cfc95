//! The camera's interior orientation and radial distortion from several
//! views of the planar target (Zhang's method): a closed-form estimate
//! from the views' homographies, then Levenberg-Marquardt on the
//! reprojection error over the intrinsics, k1, k2 and every view's pose.

use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, SymmetricEigen, Vector3};

use crate::camera::{Intrinsics, Pose};
use crate::homography::{Correspondence, HomographyError, fit_homography};
use crate::lm;

/// Fewest views accepted.
pub const MIN_VIEWS: usize = 3;

/// A fitted lens.
#[derive(Debug, Clone, PartialEq)]
pub struct IntrinsicsFit {
    /// The interior orientation and distortion.
    pub intrinsics: Intrinsics,
    /// Each view's pose.
    pub poses: Vec<Pose>,
    /// RMS reprojection error over all points, px.
    pub rms_px: f64,
}

/// Why the intrinsics could not be fitted.
#[derive(Debug, Clone, PartialEq)]
pub enum IntrinsicsError {
    /// Fewer than [`MIN_VIEWS`] views.
    TooFewViews(usize),
    /// A view's homography failed (view index, 0-based).
    View(usize, HomographyError),
    /// The views do not determine the intrinsics (e.g. all parallel to the sensor).
    Degenerate,
}

impl std::fmt::Display for IntrinsicsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::TooFewViews(n) => write!(
                f,
                "intrinsics need at least {MIN_VIEWS} views of the target, got {n}"
            ),
            Self::View(i, e) => write!(f, "view {}: {e}", i + 1),
            Self::Degenerate => write!(
                f,
                "the views do not determine the lens: tilt the target differently in each view"
            ),
        }
    }
}

/// Zhang's `v_ij` of homography `h`.
fn v(h: &Matrix3<f64>, i: usize, j: usize) -> [f64; 6] {
    let (a, b) = (h.column(i), h.column(j));
    [
        a[0] * b[0],
        a[0] * b[1] + a[1] * b[0],
        a[1] * b[1],
        a[2] * b[0] + a[0] * b[2],
        a[2] * b[1] + a[1] * b[2],
        a[2] * b[2],
    ]
}

/// Closed-form K (zero skew) from plane homographies in pixel units.
fn closed_form(hs: &[Matrix3<f64>]) -> Option<Matrix3<f64>> {
    let mut rows: Vec<[f64; 6]> = Vec::new();
    for h in hs {
        let (v11, v12, v22) = (v(h, 0, 0), v(h, 0, 1), v(h, 1, 1));
        rows.push(v12);
        rows.push(std::array::from_fn(|k| v11[k] - v22[k]));
    }
    rows.push([0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
    let vm = DMatrix::from_fn(rows.len(), 6, |r, c| rows[r][c]);
    let eig = SymmetricEigen::new(vm.transpose() * vm);
    let k = eig.eigenvalues.imin();
    // B = K⁻ᵀK⁻¹ is positive definite: pick the eigenvector's sign with B11 > 0.
    let b = eig.eigenvectors.column(k);
    let b = if b[0] < 0.0 { -b } else { b.into_owned() };
    let (b11, b12, b22, b13, b23, b33) = (b[0], b[1], b[2], b[3], b[4], b[5]);
    let v0 = (b12 * b13 - b11 * b23) / (b11 * b22 - b12 * b12);
    let lambda = b33 - (b13 * b13 + v0 * (b12 * b13 - b11 * b23)) / b11;
    let alpha = (lambda / b11).sqrt();
    let beta = (lambda * b11 / (b11 * b22 - b12 * b12)).sqrt();
    let u0 = -b13 * alpha * alpha / lambda;
    let k = Matrix3::new(alpha, 0.0, u0, 0.0, beta, v0, 0.0, 0.0, 1.0);
    k.iter().all(|x| x.is_finite()).then_some(k)
}

/// Pose of a view from its homography and K.
fn pose_from(h: &Matrix3<f64>, k_inv: &Matrix3<f64>) -> Pose {
    let a = k_inv * h;
    let mut s = 1.0 / a.column(0).norm();
    if (a * s)[(2, 2)] < 0.0 {
        s = -s; // the board is in front of the camera
    }
    let (r1, r2) = (a.column(0) * s, a.column(1) * s);
    let r = Matrix3::from_columns(&[r1, r2, r1.cross(&r2)]);
    let svd = r.svd(true, true);
    let rotation = match (svd.u, svd.v_t) {
        (Some(u), Some(vt)) => u * vt,
        _ => r,
    };
    Pose {
        rotation,
        translation: a.column(2) * s,
    }
}

/// Fits the lens to `views` (each: board mm ↔ distorted image px).
pub fn fit_intrinsics(
    views: &[Vec<Correspondence>],
    width: usize,
    height: usize,
) -> Result<IntrinsicsFit, IntrinsicsError> {
    if views.len() < MIN_VIEWS {
        return Err(IntrinsicsError::TooFewViews(views.len()));
    }
    // Pixels scaled to ~unit range for a well-conditioned closed form.
    let s = width.max(height) as f64;
    let t = Matrix3::new(
        1.0 / s,
        0.0,
        -(width as f64) / (2.0 * s),
        0.0,
        1.0 / s,
        -(height as f64) / (2.0 * s),
        0.0,
        0.0,
        1.0,
    );
    // Board in units of 100 mm: the homography's columns then have
    // comparable size (K does not depend on the board's unit).
    let unit = Matrix3::new(100.0, 0.0, 0.0, 0.0, 100.0, 0.0, 0.0, 0.0, 1.0);
    let mut hs = Vec::new();
    let mut conditioned = Vec::new();
    for (i, view) in views.iter().enumerate() {
        let fit = fit_homography(view).map_err(|e| IntrinsicsError::View(i, e))?;
        let h = t * fit.board_to_image.0;
        let c = h * unit;
        conditioned.push(c / c.norm());
        hs.push(h);
    }
    let k_scaled = closed_form(&conditioned).ok_or(IntrinsicsError::Degenerate)?;
    let t_inv = t.try_inverse().ok_or(IntrinsicsError::Degenerate)?;
    let k = t_inv * k_scaled;
    let k_inv = k.try_inverse().ok_or(IntrinsicsError::Degenerate)?;
    let mut p = vec![k[(0, 0)], k[(1, 1)], k[(0, 2)], k[(1, 2)], 0.0, 0.0];
    for h in &hs {
        let pose = pose_from(&(t_inv * h), &k_inv);
        let rv = Rotation3::from_matrix(&pose.rotation).scaled_axis();
        p.extend([
            rv.x,
            rv.y,
            rv.z,
            pose.translation.x,
            pose.translation.y,
            pose.translation.z,
        ]);
    }
    let n_points: usize = views.iter().map(Vec::len).sum();
    let residuals = |p: &DVector<f64>| {
        let (intr, poses) = unpack(p.as_slice());
        let mut r = DVector::zeros(2 * n_points);
        let mut k = 0;
        for (view, pose) in views.iter().zip(&poses) {
            for c in view {
                let x = pose.rotation * Vector3::new(c.board_mm[0], c.board_mm[1], 0.0)
                    + pose.translation;
                let q = intr.pixel_of_normalised([x.x / x.z, x.y / x.z]);
                r[k] = q[0] - c.image_px[0];
                r[k + 1] = q[1] - c.image_px[1];
                k += 2;
            }
        }
        r
    };
    let (best, sse) = lm::minimise(DVector::from_vec(p), residuals, 100);
    let (intrinsics, poses) = unpack(best.as_slice());
    let rms_px = (sse / n_points as f64).sqrt();
    if !(rms_px.is_finite() && intrinsics.fx > 0.0 && intrinsics.fy > 0.0) {
        return Err(IntrinsicsError::Degenerate);
    }
    Ok(IntrinsicsFit {
        intrinsics,
        poses,
        rms_px,
    })
}

fn unpack(p: &[f64]) -> (Intrinsics, Vec<Pose>) {
    let intr = Intrinsics {
        fx: p[0],
        fy: p[1],
        cx: p[2],
        cy: p[3],
        k1: p[4],
        k2: p[5],
    };
    let poses = p[6..]
        .chunks_exact(6)
        .map(|c| Pose {
            rotation: *Rotation3::from_scaled_axis(Vector3::new(c[0], c[1], c[2])).matrix(),
            translation: Vector3::new(c[3], c[4], c[5]),
        })
        .collect();
    (intr, poses)
}

#[cfg(test)]
mod tests;
