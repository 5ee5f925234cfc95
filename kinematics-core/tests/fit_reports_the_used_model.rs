//! The error-model fit reports the residuals of the coefficients as they
//! are used (evaluated by `Quadratic::eval`, as the firmware does), and
//! refuses measurements it cannot represent.

use kinematics_core::error_model::MAX_MEASURED_MM;
use kinematics_core::{Error, MeasuredPoint, Quadratic, fit};

mod support;
use support::noisy_grid;

fn field(p: &mut MeasuredPoint, k: usize) -> &mut f64 {
    match k {
        0 => &mut p.x_mm,
        1 => &mut p.y_mm,
        2 => &mut p.dx_mm,
        _ => &mut p.dy_mm,
    }
}

/// SSE of `coef` over the points, evaluated the firmware's way.
fn used_sse(coef: [f64; 6], points: &[MeasuredPoint], axis: usize) -> f64 {
    let q = Quadratic::new(coef);
    points
        .iter()
        .map(|p| {
            let d = if axis == 0 { p.dx_mm } else { p.dy_mm };
            let r = d - q.eval(p.x_mm, p.y_mm).unwrap();
            r * r
        })
        .sum()
}

#[test]
fn reported_sse_and_r2_are_those_of_the_coefficients_as_used() {
    let points = noisy_grid();
    assert_eq!(points.len(), 121);
    let report = fit(&points).unwrap();
    for (axis, f) in [(0, &report.dx), (1, &report.dy)] {
        let sse = used_sse(f.coef, &points, axis);
        assert_eq!(f.sse, sse, "axis {axis}: reported SSE is not the model's");
        let d: Vec<f64> = points
            .iter()
            .map(|p| if axis == 0 { p.dx_mm } else { p.dy_mm })
            .collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let sst: f64 = d.iter().map(|v| (v - mean) * (v - mean)).sum();
        assert!((f.r2 - (1.0 - sse / sst)).abs() < 1e-15, "axis {axis}");
        assert_eq!(f.rmse, Some((sse / 115.0).sqrt()));
    }
}

#[test]
fn measurements_beyond_ten_metres_or_non_finite_are_refused() {
    let base = noisy_grid();
    let limit = MAX_MEASURED_MM;
    for k in 0..4 {
        for bad in [
            1e308,
            -1e308,
            limit.next_up(),
            -limit * 1.5,
            f64::NAN,
            f64::INFINITY,
        ] {
            let mut pts = base.clone();
            *field(&mut pts[17], k) = bad;
            match fit(&pts) {
                Err(Error::MeasurementOutOfRange { index: 17, .. })
                | Err(Error::NonFinite { .. }) => {}
                other => panic!("field {k} = {bad}: {other:?}"),
            }
        }
    }
    // The reproducer: four points at ±1e308 mm with the true quadratic's
    // values elsewhere reported R² = 1 with ~0 coefficients.
    let mut pts = base.clone();
    for (p, s) in pts.iter_mut().take(4).zip([1.0, -1.0, 1.0, -1.0]) {
        p.x_mm = s * 1e308;
    }
    assert_eq!(
        fit(&pts).map(|_| ()),
        Err(Error::MeasurementOutOfRange {
            index: 0,
            what: "x_mm"
        })
    );
    // At the limit the fit still works and reports what its model does.
    let mut far = base.clone();
    far[0].x_mm = limit;
    let report = fit(&far).unwrap();
    assert_eq!(report.dx.sse, used_sse(report.dx.coef, &far, 0));
}
