use super::*;
use crate::frames::PointMm;
use crate::galvo::model::round_to_code;
use crate::galvo::{GalvoGeometry, MirrorAngles};
extern crate std;

/// The polynomial arc tangent against the `f64` one: over a dense
/// logarithmic sweep of both signs (every reduction range and its edges),
/// and the special values.
#[test]
fn atan_f32_is_within_2e7_rad_everywhere() {
    let mut worst = 0.0f64;
    let mut t = 1e-6f32;
    while t < 1e7 {
        for v in [t, -t, t.next_up(), t.next_down()] {
            let err = (f64::from(atan_f32(v)) - libm::atan(f64::from(v))).abs();
            assert!(err < 2e-7, "{v}: {err}");
            worst = worst.max(err);
        }
        t *= 1.0001;
    }
    for edge in [TAN_PI_8, TAN_3PI_8, 1.0] {
        for v in [edge, edge.next_up(), edge.next_down()] {
            let err = (f64::from(atan_f32(v)) - libm::atan(f64::from(v))).abs();
            assert!(err < 2e-7, "{v}: {err}");
        }
    }
    assert!(worst > 0.0);
    assert_eq!(atan_f32(0.0), 0.0);
    assert_eq!(atan_f32(f32::INFINITY), core::f32::consts::FRAC_PI_2);
    assert_eq!(atan_f32(f32::NEG_INFINITY), -core::f32::consts::FRAC_PI_2);
    assert!(atan_f32(f32::NAN).is_nan());
    // Odd.
    for v in [0.1f32, 0.5, 2.0, 30.0] {
        assert_eq!(atan_f32(-v), -atan_f32(v));
    }
}

/// A galvo with asymmetric, non-default mappings.
fn odd_galvo() -> Galvo<f32> {
    Galvo::<f32> {
        geometry: GalvoGeometry {
            d_mm: 350.0,
            e_mm: 12.0,
        },
        dac_x: DacAxis {
            codes_per_rad: -9000.0,
            offset_code: 2040.0,
        },
        dac_y: DacAxis {
            codes_per_rad: 9500.0,
            offset_code: 2050.5,
        },
    }
}

/// The exact (f64) code value of an axis for a board point.
fn exact_values(g: &Galvo<f32>, x: f32, y: f32) -> [f64; 2] {
    let g64: Galvo<f64> = g.cast();
    let a = g64
        .geometry
        .ik(PointMm::new(f64::from(x), f64::from(y)))
        .unwrap();
    [
        g64.dac_x.offset_code + g64.dac_x.codes_per_rad * a.x_rad,
        g64.dac_y.offset_code + g64.dac_y.codes_per_rad * a.y_rad,
    ]
}

/// Board → codes agrees with the checked `f32` path (libm's `atanf`)
/// except where the exact code value lies within 1/256 LSB of a rounding
/// tie; angles → codes agrees bit for bit; bad input is refused.
#[test]
fn sample_map_agrees_with_the_checked_path_and_refuses_bad_input() {
    let g = odd_galvo();
    let map = SampleMap::new(&g).unwrap();
    let mut differ = 0;
    for i in -60..=60 {
        for j in -60..=60 {
            let (x, y) = (i as f32 * 3.7, j as f32 * 3.3);
            let fast = map.board_to_codes(x, y).unwrap();
            let checked = g.board_to_codes(PointMm::new(x, y)).unwrap();
            let exact = exact_values(&g, x, y);
            for (a, b, v) in [(fast.x, checked.x, exact[0]), (fast.y, checked.y, exact[1])] {
                assert_eq!(a.clamped, b.clamped);
                if a.code != b.code {
                    let tie = (v - v.floor() - 0.5).abs();
                    assert!(tie < 1.0 / 256.0, "({x}, {y}): {v}");
                    differ += 1;
                }
            }
            let (tx, ty) = (i as f32 * 0.004, j as f32 * -0.0041);
            assert_eq!(
                map.angles_to_codes(tx, ty),
                g.angles_to_codes(MirrorAngles {
                    x_rad: tx,
                    y_rad: ty
                })
                .ok()
            );
        }
    }
    assert!(differ < 10, "{differ}");
    // Far outside: clamped and flagged, as the checked path.
    let far = map.board_to_codes(1e6, -1e6).unwrap();
    assert!(far.x.clamped && far.y.clamped);
    assert_eq!(map.board_to_codes(f32::NAN, 0.0), None);
    assert_eq!(map.board_to_codes(0.0, f32::INFINITY), None);
    assert_eq!(map.angles_to_codes(f32::NAN, 0.0), None);
    let mut bad = g;
    bad.dac_y.codes_per_rad = 0.0;
    assert!(matches!(
        SampleMap::new(&bad),
        Err(Error::InvalidConfig { .. })
    ));
    bad = g;
    bad.geometry.d_mm = -1.0;
    assert!(matches!(
        SampleMap::new(&bad),
        Err(Error::InvalidConfig { .. })
    ));
}

/// The block functions' codes are the per-point functions' bit for bit:
/// the fast rounding against `round_to_code` over every rounding tie
/// and its neighbours in 0..=4095, the clamps, and both blocks over a
/// grid (non-finite input holds the codes before it).
#[test]
fn blocks_equal_the_per_point_maps() {
    for k in 0..=8192u32 {
        let tie = k as f32 * 0.5 - 0.5;
        for v in [tie, tie.next_up(), tie.next_down()] {
            assert_eq!(block_code(v), round_to_code(v).code, "{v}");
        }
    }
    for v in [-1e9f32, -3.0, 0.0, 0.49999997, 1e9] {
        assert_eq!(block_code(v), round_to_code(v).code, "{v}");
    }
    let map = SampleMap::new(&odd_galvo()).unwrap();
    let points: std::vec::Vec<[f32; 2]> = (-40..=40)
        .flat_map(|i| (-40..=40).map(move |j| [i as f32 * 5.7, j as f32 * 4.9]))
        .chain([[f32::NAN, 1.0]])
        .collect();
    let mut codes = std::vec![[0u16; 2]; points.len()];
    let last = map.board_block(&points, &mut codes, [7, 9]);
    let mut hold = [7, 9];
    for (p, c) in points.iter().zip(&codes) {
        if let Some(d) = map.board_to_codes(p[0], p[1]) {
            hold = [d.x.code, d.y.code];
        }
        assert_eq!(*c, hold, "{p:?}");
    }
    assert_eq!(last, hold);
    let angles: std::vec::Vec<[f32; 2]> =
        points.iter().map(|p| [p[0] * 1e-3, p[1] * -1e-3]).collect();
    let last = map.angles_block(&angles, &mut codes, [1, 2]);
    let mut hold = [1, 2];
    for (a, c) in angles.iter().zip(&codes) {
        if let Some(d) = map.angles_to_codes(a[0], a[1]) {
            hold = [d.x.code, d.y.code];
        }
        assert_eq!(*c, hold, "{a:?}");
    }
    assert_eq!(last, hold);
    let (x, y): (std::vec::Vec<f32>, std::vec::Vec<f32>) =
        angles.iter().map(|a| (a[0], a[1])).unzip();
    let mut by_axes = std::vec![[0u16; 2]; points.len()];
    assert_eq!(map.axes_block(&x, &y, &mut by_axes, [1, 2]), last);
    assert_eq!(by_axes, codes);
}
