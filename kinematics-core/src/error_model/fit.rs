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

use super::model::{ErrorModel, MAX_MEASURED_MM, N_COEF, Quadratic};
use crate::error::Error;
use crate::numeric::{back_substitute, finite};

/// Relative size below which a diagonal entry of R means the points do not
/// determine the quadratic.
const RANK_TOL: f64 = 1e-9;

/// Smallest spread of the measured points (largest distance of a point
/// from their centroid along x or y), mm, that can determine a quadratic.
/// Closer together they are one spot for any real measurement (a board is
/// measured to ~0.1 mm), and the fit's scale-free rank check would pass:
/// its rounding noise, divided by the spread squared, came out as
/// curvature that moved the spot by tens of mm at the grid corners.
pub const MIN_SPREAD_MM: f64 = 1.0;

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
            let h = crate::numeric::hypot(pivot, ak);
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
        let qtb: [f64; N_COEF] = core::array::from_fn(|k| {
            self.qtb
                .get(k)
                .and_then(|q| q.get(axis))
                .copied()
                .unwrap_or(0.0)
        });
        back_substitute(&self.r, &qtb)
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
    Ok(finite(sse, "fit residual")?)
}

/// Fits the error quadratics of both axes to `points` by least squares.
///
/// Needs at least 6 points that determine a quadratic: not all on one line
/// (or repeated), not all on one conic, and spread over at least
/// `MIN_SPREAD_MM` (not one spot measured many times).
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
    let [sx, sy, sdx, sdy] = checked_sums(points)?;
    let norm = Normalisation::of(points, sx / nf, sy / nf)?;
    let mut qr = Qr::new();
    for p in points {
        qr.add_row(norm.basis(p.x_mm, p.y_mm), [p.dx_mm, p.dy_mm]);
    }
    qr.check_rank(n)?;
    let axis = |k: usize, mean: f64| axis_fit(points, norm.expand_to_raw(qr.solve(k)), k, mean);
    Ok(FitReport {
        dx: axis(0, sdx / nf)?,
        dy: axis(1, sdy / nf)?,
    })
}

/// Checks every position and error (finite, within ±[`MAX_MEASURED_MM`])
/// and returns their sums `[Σx, Σy, Σdx, Σdy]`, mm.
fn checked_sums(points: &[MeasuredPoint]) -> Result<[f64; 4], Error> {
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
    Ok([sx, sy, sdx, sdy])
}

impl Normalisation {
    /// Centred on `(cx, cy)` (mm) and scaled by the points' largest
    /// deviation; [`Error::DegeneratePoints`] when that is below
    /// [`MIN_SPREAD_MM`].
    fn of(points: &[MeasuredPoint], cx: f64, cy: f64) -> Result<Self, Error> {
        let scale = points
            .iter()
            .map(|p| (p.x_mm - cx).abs().max((p.y_mm - cy).abs()))
            .fold(0.0, f64::max);
        if !scale.is_finite() || scale < MIN_SPREAD_MM {
            return Err(Error::DegeneratePoints);
        }
        Ok(Self {
            cx,
            cy,
            inv_scale: 1.0 / scale,
        })
    }
}

/// The report of axis `k` (0: dx, 1: dy) for the raw coefficients `coef`;
/// `mean` is the axis' mean measured error, mm.
fn axis_fit(
    points: &[MeasuredPoint],
    coef: [f64; N_COEF],
    k: usize,
    mean: f64,
) -> Result<AxisFit, Error> {
    let n = points.len();
    let nf = n as f64;
    if !coef.iter().all(|c| c.is_finite()) {
        return Err(Error::NonFinite {
            what: "fitted coefficient",
        });
    }
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
    // The mean's own rounding leaves an SST of about n·(n·ε·|d|)² when
    // every error is the same: below that the data has no variance
    // and 1 − SSE/SST would be a ratio of two rounding noises.
    let largest = points
        .iter()
        .map(|p| if k == 0 { p.dx_mm } else { p.dy_mm }.abs())
        .fold(0.0, f64::max);
    let rounding = nf * f64::EPSILON * largest;
    let r2 = if sst > nf * rounding * rounding {
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
}

#[cfg(test)]
mod tests;
