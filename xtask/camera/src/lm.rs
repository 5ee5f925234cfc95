//! Levenberg-Marquardt least squares with a forward-difference Jacobian,
//! shared by the homography refinement and the intrinsics fit.

use nalgebra::{DMatrix, DVector};

/// Minimises `Σ r(p)²` from `start`; returns the best parameters found and
/// their residual sum of squares. `residuals` must return the same length
/// for every parameter vector; a non-finite residual vector is treated as
/// infinitely bad (the step is rejected).
pub fn minimise(
    start: DVector<f64>,
    residuals: impl Fn(&DVector<f64>) -> DVector<f64>,
    max_iterations: usize,
) -> (DVector<f64>, f64) {
    let cost = |r: &DVector<f64>| {
        let c = r.norm_squared();
        if c.is_finite() { c } else { f64::INFINITY }
    };
    let mut p = start;
    let mut r = residuals(&p);
    let mut c = cost(&r);
    let mut lambda = 1e-3;
    for _ in 0..max_iterations {
        let j = jacobian(&p, &r, &residuals);
        let jt = j.transpose();
        let jtj = &jt * &j;
        let g = &jt * &r;
        let mut improved = false;
        for _ in 0..10 {
            let mut a = jtj.clone();
            for i in 0..a.nrows() {
                a[(i, i)] += lambda * (jtj[(i, i)].max(1e-12));
            }
            let Some(step) = a.cholesky().map(|ch| ch.solve(&(-&g))) else {
                lambda *= 10.0;
                continue;
            };
            let candidate = &p + &step;
            let rc = residuals(&candidate);
            let cc = cost(&rc);
            if cc < c {
                let relative = (c - cc) / c.max(1e-300);
                p = candidate;
                r = rc;
                c = cc;
                lambda = (lambda / 10.0).max(1e-12);
                improved = relative > 1e-12;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    (p, c)
}

fn jacobian(
    p: &DVector<f64>,
    r: &DVector<f64>,
    residuals: &impl Fn(&DVector<f64>) -> DVector<f64>,
) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(r.len(), p.len());
    for k in 0..p.len() {
        let h = 1e-7 * p[k].abs().max(1e-3);
        let mut q = p.clone();
        q[k] += h;
        let rq = residuals(&q);
        j.set_column(k, &((rq - r) / h));
    }
    j
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_the_rosenbrock_valley_and_an_exponential() {
        let (p, c) = minimise(
            DVector::from_vec(vec![-1.2, 1.0]),
            |p| DVector::from_vec(vec![10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0]]),
            200,
        );
        assert!(
            (p[0] - 1.0).abs() < 1e-6 && (p[1] - 1.0).abs() < 1e-6,
            "{p}"
        );
        assert!(c < 1e-12);
        // y = 2·exp(0.3·t) sampled exactly.
        let ts: Vec<f64> = (0..10).map(f64::from).collect();
        let (p, _) = minimise(
            DVector::from_vec(vec![1.0, 0.1]),
            |p| {
                DVector::from_iterator(
                    ts.len(),
                    ts.iter()
                        .map(|&t| p[0] * (p[1] * t).exp() - 2.0 * (0.3 * t).exp()),
                )
            },
            100,
        );
        assert!(
            (p[0] - 2.0).abs() < 1e-6 && (p[1] - 0.3).abs() < 1e-8,
            "{p}"
        );
    }
}
