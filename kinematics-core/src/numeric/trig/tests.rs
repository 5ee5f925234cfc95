use super::*;
use core::f64::consts::{FRAC_PI_2, PI};
use proptest::prelude::*;

/// Distance in units in the last place (0 for equal values, ±0 equal).
fn ulps(a: f64, b: f64) -> u64 {
    if a == b {
        return 0;
    }
    let key = |v: f64| {
        let bits = v.to_bits() as i64;
        if bits < 0 { i64::MIN - bits } else { bits }
    };
    key(a).abs_diff(key(b))
}

fn assert_close_ulps(x: f64, max_ulps: u64) {
    let (s, c) = (sin(x), cos(x));
    let (ls, lc) = (libm::sin(x), libm::cos(x));
    assert!(ulps(s, ls) <= max_ulps, "sin({x:e}) = {s:e}, libm {ls:e}");
    assert!(ulps(c, lc) <= max_ulps, "cos({x:e}) = {c:e}, libm {lc:e}");
}

#[test]
fn pi_over_two_parts_are_short_and_sum_to_pi_over_two() {
    // 33 significant bits: the low 20 of the 52 stored mantissa bits are 0.
    assert_eq!(PIO2_HI.to_bits() & 0xf_ffff, 0);
    assert_eq!(PIO2_MID.to_bits() & 0xf_ffff, 0);
    assert_eq!(PIO2_HI + PIO2_MID, FRAC_PI_2);
    // π/2 − FRAC_PI_2 is cos(FRAC_PI_2) = 6.123233995736766e-17 (libm,
    // correctly rounded there); the parts reproduce it to 1e-31.
    let rest = ((PIO2_HI - FRAC_PI_2) + PIO2_MID) + PIO2_LO;
    assert!((rest - libm::cos(FRAC_PI_2)).abs() < 1e-31, "{rest:e}");
}

#[test]
fn exact_values() {
    assert_eq!(sin(0.0), 0.0);
    assert_eq!(cos(0.0), 1.0);
    assert_eq!(sin_cos(0.0), (0.0, 1.0));
    assert_eq!(sin(FRAC_PI_2), 1.0);
    assert_eq!(sin(-FRAC_PI_2), -1.0);
    assert_eq!(cos(PI), -1.0);
    assert_eq!(sin(3.0 * FRAC_PI_2), -1.0);
    // Tiny arguments: sin x = x, cos x = 1.
    assert_eq!(sin(1e-300), 1e-300);
    assert_eq!(sin(-2e-9), -2e-9);
    assert_eq!(cos(1e-9), 1.0);
    // Either side of the tiny-remainder shortcut, also next to π.
    assert_eq!(TINY, 2f64.powi(-27));
    for r in [
        TINY.next_down(),
        TINY,
        TINY.next_up(),
        1.5 * TINY,
        0.5 * TINY,
    ] {
        for x in [r, -r, PI + r, PI - r, -FRAC_PI_2 + r] {
            assert_close_ulps(x, 1);
        }
    }
}

#[test]
fn near_multiples_of_pi_over_two_within_2_ulp() {
    // The hard case for the reduction: x next to k·π/2, where sin or cos
    // is tiny and every bit of the remainder counts.
    for k in -64i32..=64 {
        let x = f64::from(k) * FRAC_PI_2;
        let mut near = x;
        for _ in 0..8 {
            assert_close_ulps(near, 2);
            near = near.next_up();
        }
        near = x;
        for _ in 0..8 {
            assert_close_ulps(near, 2);
            near = near.next_down();
        }
    }
}

#[test]
fn dense_sweep_within_2_ulp_up_to_100() {
    let n = 400_000;
    for i in 0..=n {
        let x = -100.0 + 200.0 * f64::from(i) / f64::from(n);
        assert_close_ulps(x, 2);
    }
}

#[test]
fn sin_cos_equals_sin_and_cos_bit_for_bit() {
    for i in -2_000..=2_000 {
        let x = f64::from(i) * 0.012_345_6;
        let (s, c) = sin_cos(x);
        assert_eq!(s.to_bits(), sin(x).to_bits(), "{x}");
        assert_eq!(c.to_bits(), cos(x).to_bits(), "{x}");
    }
}

#[test]
fn non_finite_in_nan_out() {
    for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert!(sin(x).is_nan());
        assert!(cos(x).is_nan());
        let (s, c) = sin_cos(x);
        assert!(s.is_nan() && c.is_nan());
    }
}

#[test]
fn beyond_the_exact_range_finite_and_degrading_gracefully() {
    // Up to 1e12 rad: within |x|·1e-15 of libm (the reduction's rounding).
    let mut x = EXACT_REDUCTION_MAX * 1.000_001;
    while x < 1e12 {
        for v in [x, -x] {
            assert!(
                (sin(v) - libm::sin(v)).abs() <= v.abs() * 1e-15,
                "sin({v:e})"
            );
            assert!(
                (cos(v) - libm::cos(v)).abs() <= v.abs() * 1e-15,
                "cos({v:e})"
            );
        }
        x *= 1.37;
    }
    // Huge arguments: finite, in [−1, 1] (the value itself is arbitrary).
    for v in [1e15, 3.3e17, 1e19, 1e300, f64::MAX, -f64::MAX, -7.7e40] {
        let (s, c) = sin_cos(v);
        assert!(
            (-1.0..=1.0).contains(&s) && (-1.0..=1.0).contains(&c),
            "{v:e}"
        );
        assert!((-1.0..=1.0).contains(&sin(v)) && (-1.0..=1.0).contains(&cos(v)));
    }
}

#[test]
fn acos_within_2_ulp_of_libm() {
    let n = 200_000;
    for i in 0..=n {
        let x = -1.0 + 2.0 * f64::from(i) / f64::from(n);
        assert!(ulps(acos(x), libm::acos(x)) <= 2, "acos({x:e})");
    }
    // Next to ±1 and 0, where the result is small, π or π/2.
    let mut d = 1e-300;
    while d < 0.5 {
        for x in [1.0 - d, -1.0 + d, d, -d] {
            assert!(ulps(acos(x), libm::acos(x)) <= 2, "acos({x:e})");
        }
        d *= 1.7;
    }
    assert_eq!(acos(1.0), 0.0);
    assert_eq!(acos(-1.0), PI);
    assert_eq!(acos(0.0), FRAC_PI_2);
    for x in [f64::NAN, 1.0 + 1e-15, -1.000_001, f64::INFINITY] {
        assert!(acos(x).is_nan(), "{x}");
    }
}

proptest! {
    #[test]
    fn acos_within_2_ulp_of_libm_anywhere(x in -1.0f64..=1.0) {
        prop_assert!(ulps(acos(x), libm::acos(x)) <= 2, "acos({:e})", x);
    }


    #[test]
    fn within_2_ulp_of_libm_up_to_100(x in -100.0f64..100.0) {
        let (s, c) = sin_cos(x);
        prop_assert!(ulps(s, libm::sin(x)) <= 2, "sin({:e})", x);
        prop_assert!(ulps(c, libm::cos(x)) <= 2, "cos({:e})", x);
    }

    #[test]
    fn within_1e_15_of_libm_up_to_1e4(x in -1e4f64..1e4) {
        let (s, c) = sin_cos(x);
        prop_assert!((s - libm::sin(x)).abs() <= 1e-15, "sin({:e})", x);
        prop_assert!((c - libm::cos(x)).abs() <= 1e-15, "cos({:e})", x);
    }

    #[test]
    fn exact_reduction_range_within_1e_15(
        x in -EXACT_REDUCTION_MAX..EXACT_REDUCTION_MAX,
    ) {
        prop_assert!((sin(x) - libm::sin(x)).abs() <= 1e-15, "sin({:e})", x);
        prop_assert!((cos(x) - libm::cos(x)).abs() <= 1e-15, "cos({:e})", x);
    }

    #[test]
    fn small_arguments_within_2_ulp(x in -1e-3f64..1e-3) {
        prop_assert!(ulps(sin(x), libm::sin(x)) <= 2, "sin({:e})", x);
        prop_assert!(ulps(cos(x), libm::cos(x)) <= 2, "cos({:e})", x);
    }
}
