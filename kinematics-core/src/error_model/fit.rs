//! Least-squares fit of the error quadratics by a streaming Givens QR on
//! normalised columns (fixed-size storage, no allocation).
//!
//! The positions are centred on their mean and scaled by their largest
//! deviation, so the basis `1, u, v, u², uv, v²` has entries in [−1, 1].
//! Each measured point is one row; Givens rotations fold it into a 6 × 6
//! upper-triangular R (and Qᵀb for both axes), so the normal equations are
//! never formed and the condition number is not squared. Back-substitution
//! gives the coefficients in the normalised basis, which are then expanded
//! exactly into the raw basis `1, x, y, x², xy, y²`.

use super::{ErrorModel, MAX_MEASURED_MM, N_COEF, Quadratic};
use crate::error::{Error, finite};

/// Relative size below which a diagonal entry of R means the points do not
/// determine the quadratic.
const RANK_TOL: f64 = 1e-9;

/// One measurement: commanded position and the error observed there (mm).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeasuredPoint {
    /// Commanded board x, mm.
    pub x_mm: f64,
    /// Commanded board y, mm.
    pub y_mm: f64,
    /// Measured x error (spot x − commanded x), mm.
    pub dx_mm: f64,
    /// Measured y error (spot y − commanded y), mm.
    pub dy_mm: f64,
}

/// Fit of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisFit {
    /// Coefficients for 1, x, y, x², xy, y² (x, y in mm; Δ in mm).
    pub coef: [f64; N_COEF],
    /// Sum of squared residuals of the model as it is used: `coef`
    /// evaluated by [`Quadratic::eval`] (the firmware's evaluation) at each
    /// point, mm².
    pub sse: f64,
    /// Coefficient of determination `1 − SSE/SST` with the SSE above (1
    /// when the errors are all equal, SST = 0).
    pub r2: f64,
    /// `√(SSE / (n − 6))`, mm; `None` for n = 6 (no residual degrees of
    /// freedom).
    pub rmse: Option<f64>,
    /// Number of points.
    pub n: usize,
}

/// Fit of both axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitReport {
    /// x error fit.
    pub dx: AxisFit,
    /// y error fit.
    pub dy: AxisFit,
}

impl FitReport {
    /// The fitted model.
    pub fn model(&self) -> ErrorModel {
        ErrorModel {
            dx: Quadratic::new(self.dx.coef),
            dy: Quadratic::new(self.dy.coef),
        }
    }
}

/// Centre and scale of the positions.
#[derive(Debug, Clone, Copy)]
struct Normalisation {
    cx: f64,
    cy: f64,
    inv_scale: f64,
}

impl Normalisation {
    fn basis(&self, x: f64, y: f64) -> [f64; N_COEF] {
        let u = (x - self.cx) * self.inv_scale;
        let v = (y - self.cy) * self.inv_scale;
        [1.0, u, v, u * u, u * v, v * v]
    }

    /// Coefficients in the raw basis from those in the normalised one:
    /// substitutes `u = a(x − cx)`, `v = a(y − cy)` and expands.
    fn expand_to_raw(&self, g: [f64; N_COEF]) -> [f64; N_COEF] {
        let [g0, g1, g2, g3, g4, g5] = g;
        let (a, cx, cy) = (self.inv_scale, self.cx, self.cy);
        let a2 = a * a;
        [
            g0 - a * (g1 * cx + g2 * cy) + a2 * (g3 * cx * cx + g4 * cx * cy + g5 * cy * cy),
            a * g1 - a2 * (2.0 * g3 * cx + g4 * cy),
            a * g2 - a2 * (g4 * cx + 2.0 * g5 * cy),
            a2 * g3,
            a2 * g4,
            a2 * g5,
        ]
    }
}

/// Streaming QR state: R (upper triangular) and Qᵀb for the two axes.
struct Qr {
    r: [[f64; N_COEF]; N_COEF],
    qtb: [[f64; 2]; N_COEF],
}

impl Qr {
    fn new() -> Self {
        Self {
            r: [[0.0; N_COEF]; N_COEF],
            qtb: [[0.0; 2]; N_COEF],
        }
    }

    /// Folds the row `(a | b)` into R by Givens rotations.
    fn add_row(&mut self, mut a: [f64; N_COEF], mut b: [f64; 2]) {
        for (k, (rk, qk)) in self.r.iter_mut().zip(self.qtb.iter_mut()).enumerate() {
            let (Some(&pivot), Some(&ak)) = (rk.get(k), a.get(k)) else {
                continue;
            };
            if ak == 0.0 {
                continue;
            }
            let h = libm::hypot(pivot, ak);
            let (c, s) = (pivot / h, ak / h);
            for (rj, aj) in rk.iter_mut().zip(a.iter_mut()).skip(k) {
                let (x, y) = (*rj, *aj);
                *rj = c * x + s * y;
                *aj = -s * x + c * y;
            }
            for (qj, bj) in qk.iter_mut().zip(b.iter_mut()) {
                let (x, y) = (*qj, *bj);
                *qj = c * x + s * y;
                *bj = -s * x + c * y;
            }
        }
    }

    /// `Err(DegeneratePoints)` if some |R_kk| is negligible against the
    /// largest column norm (√n for the constant column).
    fn check_rank(&self, n: usize) -> Result<(), Error> {
        let floor = RANK_TOL * libm::sqrt(n as f64);
        for (k, rk) in self.r.iter().enumerate() {
            match rk.get(k) {
                Some(d) if d.abs() > floor => {}
                _ => return Err(Error::DegeneratePoints),
            }
        }
        Ok(())
    }

    /// Solves R·g = Qᵀb for axis `axis` by back-substitution.
    fn solve(&self, axis: usize) -> [f64; N_COEF] {
        let mut g = [0.0; N_COEF];
        for (k, (rk, qk)) in self.r.iter().zip(self.qtb.iter()).enumerate().rev() {
            let tail: f64 = rk
                .iter()
                .zip(g.iter())
                .skip(k + 1)
                .map(|(r, x)| r * x)
                .sum();
            let rhs = qk.get(axis).copied().unwrap_or(0.0) - tail;
            let diag = rk.get(k).copied().unwrap_or(1.0);
            if let Some(gk) = g.get_mut(k) {
                *gk = rhs / diag;
            }
        }
        g
    }
}

/// Sum of squared residuals of `model` for axis `axis` (0: dx, 1: dy) over
/// `points`, mm², with the model evaluated by [`Quadratic::eval`] exactly
/// as the firmware evaluates it.
///
/// Errors: [`Error::NonFinite`] (an input, or an overflowing residual).
pub fn sse_of(model: &Quadratic, points: &[MeasuredPoint], axis: usize) -> Result<f64, Error> {
    let mut sse = 0.0;
    for p in points {
        let d = if axis == 0 { p.dx_mm } else { p.dy_mm };
        let r = finite(d, "measured error")? - model.eval(p.x_mm, p.y_mm)?;
        sse += r * r;
    }
    finite(sse, "fit residual")
}

/// Fits the error quadratics of both axes to `points` by least squares.
///
/// Needs at least 6 points that determine a quadratic: not all on one line
/// (or repeated), not all on one conic.
///
/// Every position and error must be within ±[`MAX_MEASURED_MM`] (10 m).
/// The reported SSE, R² and RMSE are those of the returned raw
/// coefficients (see [`sse_of`]), not of the internal normalised fit.
///
/// Errors: [`Error::TooFewPoints`], [`Error::NonFinite`] (a non-finite
/// input, or a fit that overflows), [`Error::MeasurementOutOfRange`],
/// [`Error::DegeneratePoints`].
pub fn fit(points: &[MeasuredPoint]) -> Result<FitReport, Error> {
    let n = points.len();
    if n < N_COEF {
        return Err(Error::TooFewPoints { n });
    }
    let nf = n as f64;
    let (mut sx, mut sy, mut sdx, mut sdy) = (0.0, 0.0, 0.0, 0.0);
    for (index, p) in points.iter().enumerate() {
        let check = |v: f64, what: &'static str| {
            let v = finite(v, what)?;
            if v.abs() > MAX_MEASURED_MM {
                return Err(Error::MeasurementOutOfRange { index, what });
            }
            Ok(v)
        };
        sx += check(p.x_mm, "x_mm")?;
        sy += check(p.y_mm, "y_mm")?;
        sdx += check(p.dx_mm, "dx_mm")?;
        sdy += check(p.dy_mm, "dy_mm")?;
    }
    let (cx, cy) = (sx / nf, sy / nf);
    let scale = points
        .iter()
        .map(|p| (p.x_mm - cx).abs().max((p.y_mm - cy).abs()))
        .fold(0.0, f64::max);
    if scale <= 0.0 || !scale.is_finite() {
        return Err(Error::DegeneratePoints);
    }
    let norm = Normalisation {
        cx,
        cy,
        inv_scale: 1.0 / scale,
    };
    let mut qr = Qr::new();
    for p in points {
        qr.add_row(norm.basis(p.x_mm, p.y_mm), [p.dx_mm, p.dy_mm]);
    }
    qr.check_rank(n)?;
    let means = [sdx / nf, sdy / nf];
    let axis = |k: usize| -> Result<AxisFit, Error> {
        let coef = norm.expand_to_raw(qr.solve(k));
        if !coef.iter().all(|c| c.is_finite()) {
            return Err(Error::NonFinite {
                what: "fitted coefficient",
            });
        }
        let mean = means.get(k).copied().unwrap_or(0.0);
        let sst: f64 = points
            .iter()
            .map(|p| {
                let d = if k == 0 { p.dx_mm } else { p.dy_mm };
                (d - mean) * (d - mean)
            })
            .sum();
        // The residuals of the raw coefficients, evaluated as the firmware
        // evaluates them: what the fit reports is what the model does.
        let sse = sse_of(&Quadratic::new(coef), points, k)?;
        if !sst.is_finite() {
            return Err(Error::NonFinite {
                what: "fit residual",
            });
        }
        let r2 = if sst > 0.0 {
            (1.0 - sse / sst).min(1.0)
        } else {
            1.0
        };
        let rmse = (n > N_COEF).then(|| libm::sqrt(sse / (n - N_COEF) as f64));
        Ok(AxisFit {
            coef,
            sse,
            r2,
            rmse,
            n,
        })
    };
    Ok(FitReport {
        dx: axis(0)?,
        dy: axis(1)?,
    })
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use proptest::prelude::*;
    use std::vec::Vec;

    fn grid(
        xs: impl Iterator<Item = f64> + Clone,
        ys: impl Iterator<Item = f64> + Clone,
        dx: impl Fn(f64, f64) -> f64,
        dy: impl Fn(f64, f64) -> f64,
    ) -> Vec<MeasuredPoint> {
        let mut v = Vec::new();
        for y in ys {
            for x in xs.clone() {
                v.push(MeasuredPoint {
                    x_mm: x,
                    y_mm: y,
                    dx_mm: dx(x, y),
                    dy_mm: dy(x, y),
                });
            }
        }
        v
    }

    #[test]
    fn orthogonal_residual_hand_computed() {
        // 3 × 3 grid u, v ∈ {−1, 0, 1} (x = 10u + 5, y = 10v − 3). The
        // residual r = v·(u² − 2/3) is orthogonal to 1, u, v, u², uv, v² on
        // this grid, so adding ε·r to a quadratic leaves its coefficients
        // unchanged and gives SSE = ε²·Σr² = ε²·4/3, RMSE = √(SSE/3) = 2ε/3.
        let q = Quadratic::new([0.3, -0.01, 0.02, 1e-4, -2e-4, 3e-4]);
        let eps = 0.05;
        let r = |x: f64, y: f64| {
            let (u, v) = ((x - 5.0) / 10.0, (y + 3.0) / 10.0);
            v * (u * u - 2.0 / 3.0)
        };
        let pts = grid(
            [-5.0, 5.0, 15.0].into_iter(),
            [-13.0, -3.0, 7.0].into_iter(),
            |x, y| q.value(x, y) + eps * r(x, y),
            |x, y| q.value(x, y),
        );
        let fit = fit(&pts).unwrap();
        for (a, b) in fit.dx.coef.iter().zip(q.coef.iter()) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        assert!((fit.dx.sse - eps * eps * 4.0 / 3.0).abs() < 1e-15);
        assert!((fit.dx.rmse.unwrap() - 2.0 * eps / 3.0).abs() < 1e-12);
        assert_eq!(fit.dx.n, 9);
        // SST by hand from the data.
        let mean = pts.iter().map(|p| p.dx_mm).sum::<f64>() / 9.0;
        let sst: f64 = pts.iter().map(|p| (p.dx_mm - mean).powi(2)).sum();
        assert!((fit.dx.r2 - (1.0 - eps * eps * 4.0 / 3.0 / sst)).abs() < 1e-12);
        // dy is an exact quadratic: zero residual, R² = 1.
        assert!(fit.dy.sse < 1e-24);
        assert!((fit.dy.r2 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn six_points_interpolate_without_rmse() {
        let q = Quadratic::new([1.0, 0.1, -0.2, 0.01, 0.02, -0.03]);
        let pts: Vec<_> = [
            (0.0, 0.0),
            (1.0, 0.0),
            (0.0, 1.0),
            (2.0, 0.0),
            (1.0, 1.0),
            (0.0, 2.0),
        ]
        .iter()
        .map(|&(x, y)| MeasuredPoint {
            x_mm: x,
            y_mm: y,
            dx_mm: q.value(x, y),
            dy_mm: 0.5,
        })
        .collect();
        let fit = fit(&pts).unwrap();
        assert_eq!(fit.dx.rmse, None);
        for (a, b) in fit.dx.coef.iter().zip(q.coef.iter()) {
            assert!((a - b).abs() < 1e-12);
        }
        // Constant dy: SST = 0 → R² reported as 1.
        assert_eq!(fit.dy.r2, 1.0);
        assert!((fit.dy.coef[0] - 0.5).abs() < 1e-14);
    }

    #[test]
    fn degenerate_inputs_are_errors() {
        let p = |x: f64, y: f64| MeasuredPoint {
            x_mm: x,
            y_mm: y,
            dx_mm: 0.1 * x,
            dy_mm: 0.0,
        };
        assert_eq!(fit(&[]), Err(Error::TooFewPoints { n: 0 }));
        let five: Vec<_> = (0..5).map(|i| p(f64::from(i), f64::from(i * i))).collect();
        assert_eq!(fit(&five), Err(Error::TooFewPoints { n: 5 }));
        // Eleven collinear points.
        let line: Vec<_> = (0..11)
            .map(|i| p(f64::from(i), 2.0 * f64::from(i) + 1.0))
            .collect();
        assert_eq!(fit(&line), Err(Error::DegeneratePoints));
        // Axis-parallel line.
        let row: Vec<_> = (0..11).map(|i| p(f64::from(i) * 10.0, 5.0)).collect();
        assert_eq!(fit(&row), Err(Error::DegeneratePoints));
        // The same point repeated.
        let same: Vec<_> = (0..8).map(|_| p(3.0, 4.0)).collect();
        assert_eq!(fit(&same), Err(Error::DegeneratePoints));
        // Twelve points on one circle: x² + y² = const makes the basis dependent.
        let circle: Vec<_> = (0..12)
            .map(|i| {
                let a = f64::from(i) * core::f64::consts::TAU / 12.0;
                p(50.0 * libm::cos(a), 50.0 * libm::sin(a))
            })
            .collect();
        assert_eq!(fit(&circle), Err(Error::DegeneratePoints));
        // Two parallel lines (a degenerate conic).
        let two: Vec<_> = (0..12)
            .map(|i| p(f64::from(i % 6), f64::from(i / 6)))
            .collect();
        assert_eq!(fit(&two), Err(Error::DegeneratePoints));
        let mut bad = line.clone();
        bad[3].dy_mm = f64::NAN;
        assert_eq!(fit(&bad), Err(Error::NonFinite { what: "dy_mm" }));
    }

    #[test]
    fn paper_style_grid_with_large_offsets_is_accurate() {
        // 11 × 11 grid, 0..1000 mm (far from the origin: the raw basis
        // would be badly conditioned), exact quadratic.
        let q = Quadratic::new([0.8, -2e-3, 1.5e-3, 4e-7, -3e-7, 2e-7]);
        let pts = grid(
            (0..11).map(|i| 1000.0 + f64::from(i) * 100.0),
            (0..11).map(|i| -500.0 + f64::from(i) * 100.0),
            |x, y| q.value(x, y),
            |x, y| -q.value(y, x),
        );
        let fit = fit(&pts).unwrap();
        for p in &pts {
            let m = fit.model();
            assert!((m.dx.value(p.x_mm, p.y_mm) - p.dx_mm).abs() < 1e-9);
            assert!((m.dy.value(p.x_mm, p.y_mm) - p.dy_mm).abs() < 1e-9);
        }
        for (a, b) in fit.dx.coef.iter().zip(q.coef.iter()) {
            assert!((a - b).abs() <= 1e-9 * b.abs().max(1e-6), "{a} vs {b}");
        }
    }

    /// Reference least squares, independent of the QR: normal equations in
    /// the raw basis solved by Gaussian elimination with partial pivoting
    /// (fine for the well-scaled data of the property test).
    #[allow(clippy::needless_range_loop)] // textbook elimination reads best indexed
    fn reference(points: &[MeasuredPoint]) -> [f64; 6] {
        let mut m = [[0.0f64; 7]; 6];
        for p in points {
            let b = [
                1.0,
                p.x_mm,
                p.y_mm,
                p.x_mm * p.x_mm,
                p.x_mm * p.y_mm,
                p.y_mm * p.y_mm,
            ];
            for i in 0..6 {
                for j in 0..6 {
                    m[i][j] += b[i] * b[j];
                }
                m[i][6] += b[i] * p.dx_mm;
            }
        }
        for col in 0..6 {
            let piv = (col..6)
                .max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))
                .unwrap();
            m.swap(col, piv);
            for row in 0..6 {
                if row != col {
                    let f = m[row][col] / m[col][col];
                    for k in col..7 {
                        m[row][k] -= f * m[col][k];
                    }
                }
            }
        }
        core::array::from_fn(|i| m[i][6] / m[i][i])
    }

    proptest! {
        #[test]
        fn matches_reference_least_squares_on_noisy_data(
            c in prop::array::uniform6(-1.0f64..1.0),
            noise in prop::collection::vec(-0.05f64..0.05, 25),
        ) {
            // 5 × 5 grid over ±1 (well conditioned for the reference).
            let q = Quadratic::new(c);
            let mut pts = grid(
                (0..5).map(|i| f64::from(i) * 0.5 - 1.0),
                (0..5).map(|i| f64::from(i) * 0.5 - 1.0),
                |x, y| q.value(x, y),
                |_, _| 0.0,
            );
            for (p, e) in pts.iter_mut().zip(&noise) {
                p.dx_mm += e;
            }
            let fit = fit(&pts).unwrap();
            let reference = reference(&pts);
            for (a, b) in fit.dx.coef.iter().zip(reference.iter()) {
                prop_assert!((a - b).abs() < 1e-9, "{} vs {}", a, b);
            }
            let sse: f64 = pts.iter().map(|p| {
                let r = p.dx_mm - Quadratic::new(reference).value(p.x_mm, p.y_mm);
                r * r
            }).sum();
            prop_assert!((fit.dx.sse - sse).abs() < 1e-9);
            prop_assert!((fit.dx.rmse.unwrap() - libm::sqrt(sse / 19.0)).abs() < 1e-9);
            prop_assert!(fit.dx.r2 <= 1.0);
        }

        #[test]
        fn exact_quadratics_are_recovered_anywhere(
            c in prop::array::uniform6(-1.0f64..1.0),
            x0 in -500.0f64..500.0, y0 in -500.0f64..500.0, pitch in 1.0f64..50.0,
        ) {
            let coef = [c[0], c[1] * 1e-2, c[2] * 1e-2, c[3] * 1e-5, c[4] * 1e-5, c[5] * 1e-5];
            let q = Quadratic::new(coef);
            let pts = grid(
                (0..7).map(|i| x0 + f64::from(i) * pitch),
                (0..5).map(|i| y0 + f64::from(i) * pitch),
                |x, y| q.value(x, y),
                |x, y| q.value(x, y) * 2.0,
            );
            let m = fit(&pts).unwrap().model();
            for p in &pts {
                prop_assert!((m.dx.value(p.x_mm, p.y_mm) - p.dx_mm).abs() < 1e-9);
                prop_assert!((m.dy.value(p.x_mm, p.y_mm) - p.dy_mm).abs() < 1e-9);
            }
        }
    }
}
