use super::*;

#[test]
fn clamp_keeps_nan_and_never_panics() {
    assert_eq!(clamp(5.0, 0.0, 1.0), 1.0);
    assert_eq!(clamp(-5.0f32, 0.0, 1.0), 0.0);
    assert_eq!(clamp(0.25, 0.0, 1.0), 0.25);
    assert!(clamp(f64::NAN, 0.0, 1.0).is_nan());
    // Misordered bounds (f64::clamp would panic): no panic.
    assert_eq!(clamp(0.5, 1.0, 0.0), 1.0);
}

#[test]
fn finite_rejects_nan_and_infinity() {
    assert_eq!(finite(1.5, "a"), Ok(1.5));
    assert_eq!(finite(-3.0, "y"), Ok(-3.0));
    assert_eq!(finite(f64::NAN, "a"), Err(NonFinite { name: "a" }));
    assert_eq!(finite(f64::INFINITY, "y"), Err(NonFinite { name: "y" }));
    assert_eq!(finite(f64::NEG_INFINITY, "b"), Err(NonFinite { name: "b" }));
}

#[test]
fn back_substitution_solves_an_upper_triangular_system() {
    // r·x = b with x = (1, −2, 3); the entries below the diagonal are not read.
    let r = [[2.0, 1.0, -1.0], [99.0, 4.0, 0.5], [99.0, 99.0, -0.25]];
    let b = [
        2.0 * 1.0 + 1.0 * -2.0 - 1.0 * 3.0,
        4.0 * -2.0 + 0.5 * 3.0,
        -0.25 * 3.0,
    ];
    assert_eq!(back_substitute(&r, &b), [1.0, -2.0, 3.0]);
    // A zero pivot gives a non-finite result (callers check it).
    let singular = [[1.0, 0.0], [0.0, 0.0]];
    assert!(
        back_substitute(&singular, &[1.0, 1.0])
            .iter()
            .any(|v| !v.is_finite())
    );
}

/// Distance in units in the last place (0 when both are the same NaN-free value).
fn ulps(a: f64, b: f64) -> u64 {
    a.to_bits().abs_diff(b.to_bits())
}

#[test]
fn hypot_handles_the_edges_like_libm() {
    for (x, y) in [
        (3.0, 4.0),
        (0.0, 0.0),
        (-0.0, 5.0),
        (1e300, 1e300),
        (f64::MAX, 1.0),
        (1e-310, 3e-310),
        (5e-324, 5e-324),
        (1e-200, 1e200),
    ] {
        assert!(ulps(hypot(x, y), libm::hypot(x, y)) <= 1, "{x} {y}");
        assert_eq!(hypot(x, y), hypot(-y, x));
    }
    assert_eq!(hypot(3.0, 4.0), 5.0);
    assert_eq!(hypot(f64::INFINITY, f64::NAN), f64::INFINITY);
    assert_eq!(hypot(f64::NAN, f64::NEG_INFINITY), f64::INFINITY);
    assert!(hypot(f64::NAN, 1.0).is_nan());
    assert!(hypot(2.0, f64::NAN).is_nan());
}

proptest::proptest! {
    #[test]
    fn hypot_is_within_one_ulp_of_libm(
        x in -1e6f64..1e6, y in -1e6f64..1e6, ex in -300i32..300, ey in -300i32..300,
    ) {
        let (x, y) = (x * libm::exp10(f64::from(ex)), y * libm::exp10(f64::from(ey)));
        proptest::prop_assert!(ulps(hypot(x, y), libm::hypot(x, y)) <= 1);
    }

    #[test]
    fn hypot_is_within_one_ulp_of_libm_at_working_scales(x in -1e4f64..1e4, y in -1e4f64..1e4) {
        proptest::prop_assert!(ulps(hypot(x, y), libm::hypot(x, y)) <= 1);
    }
}
