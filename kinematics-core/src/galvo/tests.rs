use super::*;
use crate::error::Error;
use crate::frames::PointMm;
use proptest::prelude::*;

const FIELD_RAD: f64 = 12.5 * core::f64::consts::PI / 180.0;

/// Independent model of the galvo: trace the beam through the two
/// mirrors as rotations of its direction vector (X mirror turns it by
/// 2θx about the y axis at the origin; after e mm along the optical axis
/// the Y mirror turns it by 2θy about the x axis; the board is d mm
/// further), then intersect with the board plane.
fn ray_trace(d: f64, e: f64, tx: f64, ty: f64) -> (f64, f64) {
    let (s1, c1) = libm::sincos(2.0 * tx);
    // Direction after the X mirror.
    let dir = [s1, 0.0, c1];
    // Hits the Y mirror's axis plane z = e.
    let t = e / dir[2];
    let hit = [dir[0] * t, 0.0, e];
    // Rotate about x by 2θy: (x, y, z) → (x, y cos − z sin…) toward +y.
    let (s2, c2) = libm::sincos(2.0 * ty);
    let dir = [dir[0], dir[2] * s2, dir[2] * c2];
    let t = d / dir[2];
    (hit[0] + dir[0] * t, hit[1] + dir[1] * t)
}

#[test]
fn matches_an_independent_ray_trace() {
    let g = GalvoGeometry::<f64>::default();
    for (tx, ty) in [(0.1, 0.0), (0.0, -0.2), (0.15, 0.2), (-0.2, -0.1)] {
        let p = g
            .fk(MirrorAngles {
                x_rad: tx,
                y_rad: ty,
            })
            .unwrap();
        let (x, y) = ray_trace(400.0, 10.0, tx, ty);
        assert!((p.x_mm - x).abs() < 1e-9 && (p.y_mm - y).abs() < 1e-9);
    }
}

#[test]
fn hand_computed_axes() {
    let g = GalvoGeometry::<f64>::default();
    // θy = 0: x = (d + e)·tan 2θx; 5° → 410·tan 10°.
    let p = g
        .fk(MirrorAngles {
            x_rad: 5f64.to_radians(),
            y_rad: 0.0,
        })
        .unwrap();
    assert!((p.x_mm - 410.0 * libm::tan(10f64.to_radians())).abs() < 1e-12);
    assert_eq!(p.y_mm, 0.0);
    // θx = 0: y = d·tan 2θy, no x.
    let a = g.ik(PointMm::new(0.0, 400.0)).unwrap();
    assert!((a.y_rad - 22.5f64.to_radians()).abs() < 1e-15);
    assert_eq!(a.x_rad, 0.0);
}

#[test]
fn pincushion_needs_less_x_angle_off_axis() {
    // The same board x at larger |y| has a longer beam path: smaller θx.
    let g = GalvoGeometry::<f64>::default();
    let on = g.ik(PointMm::new(100.0, 0.0)).unwrap();
    let off = g.ik(PointMm::new(100.0, 150.0)).unwrap();
    assert!(off.x_rad < on.x_rad);
}

#[test]
fn dac_mapping_spec_values() {
    let dac = DacAxis::<f64>::default();
    let deg = |d: f64| d.to_radians();
    assert_eq!(dac.angle_to_code(deg(12.5)).unwrap().code, 4095);
    assert_eq!(dac.angle_to_code(deg(-12.5)).unwrap().code, 0);
    // round(2047.5) = 2048 (half away from zero).
    assert_eq!(dac.angle_to_code(0.0).unwrap().code, 2048);
    // One LSB ≈ 0.0061° mechanical ≈ 0.085 mm at 400 mm (SPEC).
    let lsb_rad = dac.code_to_angle(2049).unwrap() - dac.code_to_angle(2048).unwrap();
    assert!((lsb_rad.to_degrees() - 0.0061).abs() < 0.00005);
    let lsb_mm = 400.0 * libm::tan(2.0 * lsb_rad);
    assert!((lsb_mm - 0.085).abs() < 0.001, "{lsb_mm}");
    let over = dac.angle_to_code(deg(13.0)).unwrap();
    assert_eq!(
        over,
        DacCode {
            code: 4095,
            clamped: true
        }
    );
    let under = dac.angle_to_code(deg(-20.0)).unwrap();
    assert_eq!(
        under,
        DacCode {
            code: 0,
            clamped: true
        }
    );
    assert!(!dac.angle_to_code(deg(12.49)).unwrap().clamped);
}

#[test]
fn errors_instead_of_nan() {
    let g = Galvo::<f32>::default();
    assert_eq!(
        g.board_to_codes(PointMm::new(f32::NAN, 0.0)),
        Err(Error::NonFinite { what: "x_mm" })
    );
    assert_eq!(
        g.dac_x.angle_to_code(f32::INFINITY),
        Err(Error::NonFinite { what: "DAC code" })
    );
    assert_eq!(
        g.codes_to_board(4096, 0),
        Err(Error::DacCodeOutOfRange { code: 4096 })
    );
    assert_eq!(
        g.geometry.fk(MirrorAngles {
            x_rad: 0.8,
            y_rad: 0.0
        }),
        Err(Error::MissesBoard)
    );
    assert_eq!(
        g.geometry.fk(MirrorAngles {
            x_rad: 0.0,
            y_rad: f32::NAN
        }),
        Err(Error::NonFinite { what: "y_rad" })
    );
    let flat = GalvoGeometry::<f64> {
        d_mm: 0.0,
        e_mm: 10.0,
    };
    assert!(matches!(
        flat.ik(PointMm::new(1.0, 1.0)),
        Err(Error::InvalidConfig { .. })
    ));
    let neg_e = GalvoGeometry::<f64> {
        d_mm: 400.0,
        e_mm: f64::NAN,
    };
    assert!(matches!(
        neg_e.fk(MirrorAngles::default()),
        Err(Error::InvalidConfig { .. })
    ));
    let dead = DacAxis::<f64> {
        codes_per_rad: 0.0,
        offset_code: 2047.5,
    };
    assert!(matches!(
        dead.code_to_angle(10),
        Err(Error::InvalidConfig { .. })
    ));
}

#[test]
fn every_code_round_trips() {
    let g64 = Galvo::<f64>::default();
    let g32 = Galvo::<f32>::default();
    for code in 0..=DAC_MAX_CODE {
        let a = g64.dac_x.code_to_angle(code).unwrap();
        assert_eq!(g64.dac_x.angle_to_code(a).unwrap().code, code);
        let a = g32.dac_y.code_to_angle(code).unwrap();
        let c = g32.dac_y.angle_to_code(a).unwrap();
        assert_eq!((c.code, c.clamped), (code, false));
    }
}

/// Round half away from zero in f64, clamped to the DAC range.
fn reference_code(value: f64) -> (u16, bool) {
    let r = libm::round(value);
    if r < 0.0 {
        (0, true)
    } else if r > 4095.0 {
        (4095, true)
    } else {
        (r as u16, false)
    }
}

#[test]
fn direct_conversion_rounds_half_away_and_clamps() {
    // Identity mapping: the code value is the angle itself, so every
    // f32 near each half-integer tie and both range ends is exercised.
    let dac = DacAxis::<f32> {
        codes_per_rad: 1.0,
        offset_code: 0.0,
    };
    let near = |k: i32| {
        let tie = k as f32 + 0.5;
        // Ties are exact in f32 here; their neighbours one ulp away.
        let below = if tie > 0.0 {
            tie.to_bits() - 1
        } else {
            tie.to_bits() + 1
        };
        let above = if tie > 0.0 {
            tie.to_bits() + 1
        } else {
            tie.to_bits() - 1
        };
        [
            tie,
            f32::from_bits(below),
            f32::from_bits(above),
            k as f32,
            k as f32 + 0.25,
        ]
    };
    let extremes = [
        [-0.0, 1e-30, -1e-30, -0.49999997, 0.49999997],
        [-1e9, 1e9, -0.5, 4095.5, 4095.4998],
    ];
    for v in (-3..=4099)
        .flat_map(near)
        .chain(extremes.into_iter().flatten())
    {
        let got = dac.angle_to_code(v).unwrap();
        let (code, clamped) = reference_code(f64::from(v));
        assert_eq!((got.code, got.clamped), (code, clamped), "{v}");
    }
}

/// The f32 per-sample path against the f64 reference over the whole
/// field: for every board point (as the f32 path receives it), the
/// f32 IK + DAC code is within half an LSB of the exact (f64) code
/// value, plus the f32 rounding of that value (< 1/256 LSB), i.e. it
/// differs from the f64 code only where the exact value is within
/// 1/256 LSB of a rounding tie.
#[test]
fn f32_codes_within_half_an_lsb_of_f64_over_the_field() {
    const TOL: f64 = 1.0 / 256.0;
    let g64 = Galvo::<f64>::default();
    let g32 = Galvo::<f32>::default();
    let map = SampleMap::new(&g32).unwrap();
    let value = |dac: &DacAxis<f64>, theta: f64| dac.offset_code + dac.codes_per_rad * theta;
    let (mut worst, mut differ, mut n) = (0.0f64, 0u32, 0u32);
    // 801 × 801 mirror-angle grid over ±12.5°, mapped to board points.
    for i in 0..=800 {
        for j in 0..=800 {
            let tx = FIELD_RAD * (f64::from(i) / 400.0 - 1.0) * 0.9999;
            let ty = FIELD_RAD * (f64::from(j) / 400.0 - 1.0) * 0.9999;
            let p = g64
                .geometry
                .fk(MirrorAngles {
                    x_rad: tx,
                    y_rad: ty,
                })
                .unwrap();
            let p32 = PointMm::new(p.x_mm as f32, p.y_mm as f32);
            // The per-sample map (polynomial atan) and the checked f32
            // path (libm's atanf) alike.
            let per_sample = map.board_to_codes(p32.x_mm, p32.y_mm).unwrap();
            let checked = g32.board_to_codes(p32).unwrap();
            let a64 = g64
                .geometry
                .ik(PointMm::new(f64::from(p32.x_mm), f64::from(p32.y_mm)))
                .unwrap();
            let c64 = g64.angles_to_codes(a64).unwrap();
            for (code, dac, theta, reference) in [
                (per_sample.x, &g64.dac_x, a64.x_rad, c64.x),
                (per_sample.y, &g64.dac_y, a64.y_rad, c64.y),
                (checked.x, &g64.dac_x, a64.x_rad, c64.x),
                (checked.y, &g64.dac_y, a64.y_rad, c64.y),
            ] {
                assert!(!code.clamped);
                let exact = value(dac, theta);
                let off = (f64::from(code.code) - exact).abs();
                assert!(off <= 0.5 + TOL, "({tx}, {ty}): {off} LSB");
                worst = worst.max(off - 0.5);
                differ += u32::from(code.code != reference.code);
                n += 1;
            }
        }
    }
    // Almost every code is identical; the rest sit on a tie.
    assert!(differ * 1000 < n, "{differ} of {n} codes differ");
    assert!(worst <= TOL, "{worst}");
}

#[test]
fn spanning_other_ranges() {
    // ±20° over the 12-bit range: 20° → 4095, 10° → round(3071.25).
    let dac = DacAxis::<f64>::spanning(20.0).unwrap();
    assert_eq!(dac.angle_to_code(20f64.to_radians()).unwrap().code, 4095);
    assert_eq!(dac.angle_to_code(10f64.to_radians()).unwrap().code, 3071);
    assert!(matches!(
        DacAxis::<f32>::spanning(0.0),
        Err(Error::InvalidConfig { .. })
    ));
    assert_eq!(
        DacAxis::<f32>::spanning(f64::NAN),
        Err(Error::NonFinite {
            what: "half_range_deg"
        })
    );
}

#[test]
fn cast_keeps_the_values() {
    let g = Galvo::<f64>::default().cast::<f32>();
    assert_eq!(g, Galvo::<f32>::default());
    let back = g.cast::<f64>();
    assert!((back.dac_x.codes_per_rad - Galvo::<f64>::default().dac_x.codes_per_rad).abs() < 1e-3);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn fk_of_ik_is_identity(x in -250.0f64..250.0, y in -250.0f64..250.0, d in 50.0f64..1000.0, e in 0.0f64..50.0) {
        let g = GalvoGeometry { d_mm: d, e_mm: e };
        let p = g.fk(g.ik(PointMm::new(x, y)).unwrap()).unwrap();
        prop_assert!((p.x_mm - x).abs() < 1e-9 && (p.y_mm - y).abs() < 1e-9);
    }

    #[test]
    fn ik_of_fk_is_identity(tx in -FIELD_RAD..FIELD_RAD, ty in -FIELD_RAD..FIELD_RAD) {
        let g = GalvoGeometry::<f64>::default();
        let a = g.ik(g.fk(MirrorAngles { x_rad: tx, y_rad: ty }).unwrap()).unwrap();
        prop_assert!((a.x_rad - tx).abs() < 1e-14 && (a.y_rad - ty).abs() < 1e-14);
    }

    #[test]
    fn angle_code_angle_within_half_an_lsb(t in -FIELD_RAD..FIELD_RAD) {
        let dac = DacAxis::<f64>::default();
        let c = dac.angle_to_code(t).unwrap();
        prop_assert!(!c.clamped);
        let back = dac.code_to_angle(c.code).unwrap();
        prop_assert!((back - t).abs() * dac.codes_per_rad <= 0.5 + 1e-9);
    }

    // The f32 per-sample path against the f64 reference over the field.
    #[test]
    fn f32_matches_f64_within_a_micron(tx in -FIELD_RAD..FIELD_RAD, ty in -FIELD_RAD..FIELD_RAD) {
        let g64 = Galvo::<f64>::default();
        let g32 = Galvo::<f32>::default();
        let a32 = MirrorAngles { x_rad: tx as f32, y_rad: ty as f32 };
        let a64 = MirrorAngles { x_rad: f64::from(a32.x_rad), y_rad: f64::from(a32.y_rad) };
        // FK: same angles, both precisions.
        let p64 = g64.geometry.fk(a64).unwrap();
        let p32 = g32.geometry.fk(a32).unwrap();
        prop_assert!((f64::from(p32.x_mm) - p64.x_mm).abs() < 1e-3);
        prop_assert!((f64::from(p32.y_mm) - p64.y_mm).abs() < 1e-3);
        // IK: the f32 angles for a target land within 0.001 mm of it.
        let target = PointMm::new(p64.x_mm as f32, p64.y_mm as f32);
        let ik32 = g32.geometry.ik(target).unwrap();
        let landed = g64.geometry.fk(MirrorAngles {
            x_rad: f64::from(ik32.x_rad), y_rad: f64::from(ik32.y_rad),
        }).unwrap();
        prop_assert!((landed.x_mm - f64::from(target.x_mm)).abs() < 1e-3);
        prop_assert!((landed.y_mm - f64::from(target.y_mm)).abs() < 1e-3);
        // DAC codes agree except at a rounding boundary (±1 code).
        let c64 = g64.board_to_codes(PointMm::new(f64::from(target.x_mm), f64::from(target.y_mm))).unwrap();
        let c32 = g32.board_to_codes(target).unwrap();
        prop_assert!((i32::from(c64.x.code) - i32::from(c32.x.code)).abs() <= 1);
        prop_assert!((i32::from(c64.y.code) - i32::from(c32.y.code)).abs() <= 1);
    }
}
