use super::*;
use crate::noise::Noise;

/// A 200 × 150 printed pattern (white 160 DN, grey 120 DN) and the same
/// with Gaussian spots (centre px, σ px, peak DN on white) scattered by
/// the print, then clipped: both with noise.
fn frames(spots: &[([f64; 2], f64, f64)], seed: u64) -> (GrayImage, GrayImage) {
    let (w, h) = (200, 150);
    let base: Vec<f64> = (0..w * h)
        .map(|i| 120.0 + 40.0 * (((i % w) / 9 + (i / w) / 13) % 2) as f64)
        .collect();
    let mut n = Noise::new(seed);
    let mut noisy = |v: f64| (v + 2.0 * n.normal()).round().clamp(0.0, 255.0) as u8;
    let bg = GrayImage {
        width: w,
        height: h,
        pixels: base.iter().map(|&v| noisy(v)).collect(),
    };
    let lit = base
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let (x, y) = ((i % w) as f64, (i / w) as f64);
            let add: f64 = v / 160.0
                * spots
                    .iter()
                    .map(|(c, s, p)| {
                        p * (-((x - c[0]).powi(2) + (y - c[1]).powi(2)) / (2.0 * s * s)).exp()
                    })
                    .sum::<f64>();
            noisy(v + add)
        })
        .collect();
    (
        bg,
        GrayImage {
            width: w,
            height: h,
            pixels: lit,
        },
    )
}

#[test]
fn centroid_is_sub_pixel_with_a_saturated_core() {
    let mut worst: f64 = 0.0;
    for k in 0..20u32 {
        let c = [60.0 + 3.37 * f64::from(k), 40.0 + 2.91 * f64::from(k)];
        let (bg, f) = frames(&[(c, 1.8, 500.0)], u64::from(k));
        let s = detect_spot(&bg, &f).unwrap();
        assert!(s.saturated > 4, "the core saturates: {s:?}");
        worst = worst.max((s.image_px[0] - c[0]).hypot(s.image_px[1] - c[1]));
        assert!(s.sigma_px > 0.0 && s.sigma_px < 0.1, "{s:?}");
    }
    assert!(worst < 0.08, "worst centroid error {worst} px");
}

#[test]
fn a_faint_reflection_is_ignored_and_two_spots_are_refused() {
    let (bg, f) = frames(&[([80.0, 70.0], 1.8, 400.0), ([150.0, 30.0], 1.2, 28.0)], 1);
    let s = detect_spot(&bg, &f).unwrap();
    assert_eq!(s.reflections, 1, "{s:?}");
    assert!(
        (s.image_px[0] - 80.0).abs() < 0.1 && (s.image_px[1] - 70.0).abs() < 0.1,
        "{s:?}"
    );
    let (bg, f) = frames(
        &[([80.0, 70.0], 1.8, 400.0), ([150.0, 30.0], 1.8, 300.0)],
        2,
    );
    let Err(SpotError::TwoSpots { at }) = detect_spot(&bg, &f) else {
        panic!("two spots accepted")
    };
    assert!(
        (at[0][0] - 80.0).abs() < 0.5 && (at[1][0] - 150.0).abs() < 0.5,
        "{at:?}"
    );
}

#[test]
fn frames_without_a_usable_spot_are_refused() {
    let (bg, f) = frames(&[], 3);
    assert_eq!(detect_spot(&bg, &f), Err(SpotError::NoSpot));
    let black = GrayImage::filled(200, 150, 3);
    assert_eq!(detect_spot(&bg, &black), Err(SpotError::Black));
    let white = GrayImage::filled(200, 150, 255);
    assert!(
        matches!(detect_spot(&bg, &white), Err(SpotError::Saturated { percent }) if percent > 99.0)
    );
    assert_eq!(
        detect_spot(&bg, &GrayImage::filled(20, 150, 100)),
        Err(SpotError::SizeMismatch)
    );
    for e in [
        SpotError::NoSpot,
        SpotError::Black,
        SpotError::Saturated { percent: 50.0 },
    ] {
        assert!(!e.to_string().is_empty());
    }
}
