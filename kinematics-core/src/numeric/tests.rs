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
