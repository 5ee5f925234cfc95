//! Plane-to-image homography: normalised DLT (Hartley) refined by
//! Levenberg-Marquardt on the reprojection error in the image.

use nalgebra::{DMatrix, DVector, Matrix2, Matrix3, SymmetricEigen, Vector3};

use crate::lm;

/// A board point (mm) and where it appears in the image (px).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Correspondence {
    /// Board coordinates, mm (board frame B, SPEC §4.1).
    pub board_mm: [f64; 2],
    /// Image coordinates, px (x right, y down, pixel centres at integers).
    pub image_px: [f64; 2],
}

/// A projective map of the plane (here: board mm → image px).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Homography(pub Matrix3<f64>);

impl Homography {
    /// Maps `p`; `None` on the line at infinity or for non-finite input.
    pub fn apply(&self, p: [f64; 2]) -> Option<[f64; 2]> {
        let v = self.0 * Vector3::new(p[0], p[1], 1.0);
        let out = [v.x / v.z, v.y / v.z];
        (v.z.abs() > 1e-12 && out.iter().all(|c| c.is_finite())).then_some(out)
    }

    /// The inverse map, if the matrix is invertible.
    pub fn inverse(&self) -> Option<Homography> {
        self.0.try_inverse().map(Homography)
    }

    /// ∂apply/∂p at `p` (rows: output x, y).
    pub fn jacobian(&self, p: [f64; 2]) -> Matrix2<f64> {
        let m = &self.0;
        let w = m[(2, 0)] * p[0] + m[(2, 1)] * p[1] + m[(2, 2)];
        let u = m[(0, 0)] * p[0] + m[(0, 1)] * p[1] + m[(0, 2)];
        let v = m[(1, 0)] * p[0] + m[(1, 1)] * p[1] + m[(1, 2)];
        Matrix2::new(
            (m[(0, 0)] * w - u * m[(2, 0)]) / (w * w),
            (m[(0, 1)] * w - u * m[(2, 1)]) / (w * w),
            (m[(1, 0)] * w - v * m[(2, 0)]) / (w * w),
            (m[(1, 1)] * w - v * m[(2, 1)]) / (w * w),
        )
    }
}

/// A fitted homography board mm → image px with its reprojection error.
#[derive(Debug, Clone, PartialEq)]
pub struct HomographyFit {
    /// Board mm → image px.
    pub board_to_image: Homography,
    /// Image px → board mm.
    pub image_to_board: Homography,
    /// RMS distance between measured and reprojected image points, px.
    pub rms_px: f64,
    /// Largest such distance, px.
    pub worst_px: f64,
    /// Number of correspondences used.
    pub n: usize,
}

/// Why a homography could not be fitted.
#[derive(Debug, Clone, PartialEq)]
pub enum HomographyError {
    /// Fewer than 4 correspondences (found this many).
    TooFewPoints(usize),
    /// A coordinate is NaN or infinite.
    NotFinite,
    /// The points are (nearly) collinear or coincident.
    Degenerate,
}

impl std::fmt::Display for HomographyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::TooFewPoints(n) => write!(f, "a homography needs at least 4 points, found {n}"),
            Self::NotFinite => write!(f, "a point coordinate is not a finite number"),
            Self::Degenerate => write!(f, "the points are collinear or coincident"),
        }
    }
}

/// Similarity moving points to mean 0 and mean distance √2 (Hartley).
fn normaliser(points: impl Iterator<Item = [f64; 2]> + Clone) -> Option<Matrix3<f64>> {
    let n = points.clone().count() as f64;
    let (sx, sy) = points
        .clone()
        .fold((0.0, 0.0), |(a, b), p| (a + p[0], b + p[1]));
    let (mx, my) = (sx / n, sy / n);
    let mean_dist = points.map(|p| (p[0] - mx).hypot(p[1] - my)).sum::<f64>() / n;
    if mean_dist.is_nan() || mean_dist <= 1e-12 {
        return None;
    }
    let s = std::f64::consts::SQRT_2 / mean_dist;
    Some(Matrix3::new(
        s,
        0.0,
        -s * mx,
        0.0,
        s,
        -s * my,
        0.0,
        0.0,
        1.0,
    ))
}

fn transform(t: &Matrix3<f64>, p: [f64; 2]) -> [f64; 2] {
    [t[(0, 0)] * p[0] + t[(0, 2)], t[(1, 1)] * p[1] + t[(1, 2)]]
}

/// Fits board mm → image px to `pairs` (at least 4, not collinear):
/// normalised DLT, then Levenberg-Marquardt on the image residuals.
pub fn fit_homography(pairs: &[Correspondence]) -> Result<HomographyFit, HomographyError> {
    if pairs.len() < 4 {
        return Err(HomographyError::TooFewPoints(pairs.len()));
    }
    if pairs
        .iter()
        .any(|c| c.board_mm.iter().chain(&c.image_px).any(|v| !v.is_finite()))
    {
        return Err(HomographyError::NotFinite);
    }
    let tb = normaliser(pairs.iter().map(|c| c.board_mm)).ok_or(HomographyError::Degenerate)?;
    let ti = normaliser(pairs.iter().map(|c| c.image_px)).ok_or(HomographyError::Degenerate)?;
    let norm: Vec<([f64; 2], [f64; 2])> = pairs
        .iter()
        .map(|c| (transform(&tb, c.board_mm), transform(&ti, c.image_px)))
        .collect();
    let h0 = dlt(&norm)?;
    let residuals = |h: &DVector<f64>| {
        let m = Homography(Matrix3::from_row_slice(h.as_slice()));
        let mut r = DVector::zeros(2 * norm.len());
        for (k, (b, i)) in norm.iter().enumerate() {
            let p = m.apply(*b).unwrap_or([f64::INFINITY; 2]);
            r[2 * k] = p[0] - i[0];
            r[2 * k + 1] = p[1] - i[1];
        }
        r
    };
    let (h, _) = lm::minimise(DVector::from_row_slice(h0.as_slice()), residuals, 50);
    let refined = Matrix3::from_row_slice(h.as_slice());
    let ti_inv = ti.try_inverse().ok_or(HomographyError::Degenerate)?;
    let mut m = ti_inv * refined * tb;
    m /= m.norm();
    let board_to_image = Homography(m);
    let image_to_board = board_to_image
        .inverse()
        .ok_or(HomographyError::Degenerate)?;
    let errors: Vec<f64> = pairs
        .iter()
        .map(|c| {
            board_to_image.apply(c.board_mm).map_or(f64::INFINITY, |p| {
                (p[0] - c.image_px[0]).hypot(p[1] - c.image_px[1])
            })
        })
        .collect();
    let rms_px = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    let worst_px = errors.iter().copied().fold(0.0, f64::max);
    if !rms_px.is_finite() {
        return Err(HomographyError::Degenerate);
    }
    Ok(HomographyFit {
        board_to_image,
        image_to_board,
        rms_px,
        worst_px,
        n: pairs.len(),
    })
}

/// Direct linear transform on normalised points: the right singular
/// vector of the 2n×9 system with the smallest singular value.
fn dlt(norm: &[([f64; 2], [f64; 2])]) -> Result<Matrix3<f64>, HomographyError> {
    let mut a = DMatrix::zeros(2 * norm.len(), 9);
    for (k, ([x, y], [u, v])) in norm.iter().enumerate() {
        let r1 = [-x, -y, -1.0, 0.0, 0.0, 0.0, u * x, u * y, *u];
        let r2 = [0.0, 0.0, 0.0, -x, -y, -1.0, v * x, v * y, *v];
        for j in 0..9 {
            a[(2 * k, j)] = r1[j];
            a[(2 * k + 1, j)] = r2[j];
        }
    }
    let ata = a.transpose() * &a;
    let eig = SymmetricEigen::new(ata);
    let mut order: Vec<usize> = (0..9).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let (smallest, next) = (eig.eigenvalues[order[0]], eig.eigenvalues[order[1]]);
    // A unique solution needs a one-dimensional null space: with
    // collinear points a second eigenvalue is (near) zero too.
    if next.is_nan() || next <= 1e-9 * eig.eigenvalues.max() || !smallest.is_finite() {
        return Err(HomographyError::Degenerate);
    }
    let h = eig.eigenvectors.column(order[0]);
    Ok(Matrix3::from_row_slice(h.as_slice()))
}

#[cfg(test)]
mod tests;
