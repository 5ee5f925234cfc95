use super::*;
use crate::noise::Noise;

fn truth() -> Homography {
    // A camera ~25° off the board normal: strong perspective.
    Homography(Matrix3::new(
        3.1, 0.4, 640.0, -0.2, -2.6, 360.0, 0.0004, -0.0011, 1.0,
    ))
}

fn board_grid() -> Vec<[f64; 2]> {
    let mut pts = Vec::new();
    for i in -4..=4 {
        for j in -3..=3 {
            pts.push([f64::from(i) * 30.0, f64::from(j) * 25.0]);
        }
    }
    pts
}

fn pairs(noise_px: f64, seed: u64) -> Vec<Correspondence> {
    let mut n = Noise::new(seed);
    board_grid()
        .into_iter()
        .map(|b| {
            let p = truth().apply(b).unwrap();
            Correspondence {
                board_mm: b,
                image_px: [p[0] + noise_px * n.normal(), p[1] + noise_px * n.normal()],
            }
        })
        .collect()
}

#[test]
fn recovers_an_exact_homography() {
    let fit = fit_homography(&pairs(0.0, 1)).unwrap();
    assert!(fit.rms_px < 1e-8 && fit.worst_px < 1e-7, "{fit:?}");
    for b in [[0.0, 0.0], [100.0, -70.0], [-133.0, 91.0]] {
        let p = fit.board_to_image.apply(b).unwrap();
        let q = truth().apply(b).unwrap();
        assert!((p[0] - q[0]).abs() < 1e-7 && (p[1] - q[1]).abs() < 1e-7);
        let back = fit.image_to_board.apply(p).unwrap();
        assert!((back[0] - b[0]).abs() < 1e-8 && (back[1] - b[1]).abs() < 1e-8);
    }
}

#[test]
fn noisy_points_give_the_noise_as_reprojection_error_and_an_accurate_map() {
    let fit = fit_homography(&pairs(0.3, 2)).unwrap();
    // 63 points, 8 parameters: RMS ≈ 0.3·√2·√(55/63) px.
    assert!(fit.rms_px > 0.3 && fit.rms_px < 0.5, "{}", fit.rms_px);
    let worst_map_px = board_grid()
        .into_iter()
        .map(|b| {
            let p = fit.board_to_image.apply(b).unwrap();
            let q = truth().apply(b).unwrap();
            (p[0] - q[0]).hypot(p[1] - q[1])
        })
        .fold(0.0, f64::max);
    assert!(worst_map_px < 0.25, "{worst_map_px}");
}

#[test]
fn refinement_beats_the_plain_dlt_under_anisotropic_noise() {
    // Noise on a few far points pulls the algebraic DLT more than the
    // geometric fit: the refined RMS can be no worse.
    let mut p = pairs(0.05, 3);
    p[0].image_px[0] += 4.0;
    let fit = fit_homography(&p).unwrap();
    let tb = normaliser(p.iter().map(|c| c.board_mm)).unwrap();
    let ti = normaliser(p.iter().map(|c| c.image_px)).unwrap();
    let norm: Vec<_> = p
        .iter()
        .map(|c| (transform(&tb, c.board_mm), transform(&ti, c.image_px)))
        .collect();
    let plain = Homography(ti.try_inverse().unwrap() * dlt(&norm).unwrap() * tb);
    let rms = |h: &Homography| {
        (p.iter()
            .map(|c| {
                let q = h.apply(c.board_mm).unwrap();
                (q[0] - c.image_px[0]).powi(2) + (q[1] - c.image_px[1]).powi(2)
            })
            .sum::<f64>()
            / p.len() as f64)
            .sqrt()
    };
    assert!(
        fit.rms_px <= rms(&plain) + 1e-9,
        "{} vs {}",
        fit.rms_px,
        rms(&plain)
    );
}

#[test]
fn bad_point_sets_are_refused() {
    let p = pairs(0.0, 1);
    assert_eq!(
        fit_homography(&p[..3]),
        Err(HomographyError::TooFewPoints(3))
    );
    let collinear: Vec<Correspondence> = (0..6)
        .map(|k| Correspondence {
            board_mm: [f64::from(k) * 10.0, 0.0],
            image_px: [f64::from(k) * 31.0 + 5.0, 200.0],
        })
        .collect();
    assert_eq!(fit_homography(&collinear), Err(HomographyError::Degenerate));
    let mut nan = p.clone();
    nan[2].image_px[1] = f64::NAN;
    assert_eq!(fit_homography(&nan), Err(HomographyError::NotFinite));
}

#[test]
fn jacobian_matches_finite_differences() {
    let h = truth();
    let p = [37.0, -21.0];
    let j = h.jacobian(p);
    let e = 1e-5;
    for k in 0..2 {
        let mut q = p;
        q[k] += e;
        let (a, b) = (h.apply(q).unwrap(), h.apply(p).unwrap());
        for r in 0..2 {
            assert!(((a[r] - b[r]) / e - j[(r, k)]).abs() < 1e-4);
        }
    }
}
