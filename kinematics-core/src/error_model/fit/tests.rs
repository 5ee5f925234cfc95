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
fn points_on_a_nanometre_patch_are_degenerate_not_a_board_wide_model() {
    // The SPEC grid shrunk to a 0.2 µm patch, constant error: one spot
    // measured 117 times. The normalised fit's rounding noise, divided
    // by the patch size squared, used to come out as curvature that
    // moved the spot by tens of mm at the grid corners.
    let pts = grid(
        (-6..=6).map(|i| f64::from(i) * 19.16e-9),
        (-4..=4).map(|i| f64::from(i) * 19.16e-9),
        |_, _| 0.1,
        |_, _| -0.2,
    );
    assert_eq!(fit(&pts), Err(Error::DegeneratePoints));
    // Spread over a millimetre it is a (well-determined) fit.
    let q = Quadratic::new([0.1, 1e-3, -2e-3, 3e-4, 1e-4, -2e-4]);
    let pts = grid(
        (-6..=6).map(|i| 5.0 + f64::from(i) / 6.0),
        (-4..=4).map(|i| 5.0 + f64::from(i) / 4.0),
        |x, y| q.value(x, y),
        |_, _| 0.0,
    );
    let fit = fit(&pts).unwrap();
    for (a, b) in fit.dx.coef.iter().zip(q.coef.iter()) {
        assert!((a - b).abs() < 1e-9, "{:?}", fit.dx.coef);
    }
}

#[test]
fn a_constant_error_is_a_perfect_fit_whatever_the_rounding_of_its_mean() {
    // dx = 0.1 mm everywhere: SST is rounding noise (~1e-30 mm²), and
    // 1 − SSE/SST of two rounding noises used to report R² = 0.74.
    let pts = grid(
        (-6..=6).map(|i| f64::from(i) * 19.16 * 50.0),
        (-4..=4).map(|i| f64::from(i) * 19.16 * 50.0),
        |_, _| 0.1,
        |x, _| 1e-3 * x,
    );
    let fit = fit(&pts).unwrap();
    assert_eq!(fit.dx.r2, 1.0, "{:?}", fit.dx);
    assert!(fit.dx.sse < 1e-20);
    assert!((fit.dy.r2 - 1.0).abs() < 1e-12);
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
