use super::*;
use proptest::prelude::*;

fn close<const R: usize, const C: usize>(a: &Matrix<R, C>, b: &Matrix<R, C>, tol: f64) -> bool {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .all(|(x, y)| (x - y).abs() <= tol * (1.0 + y.abs()))
}

#[test]
fn solve_recovers_known_solution_with_pivoting() {
    // The (0,0) entry is zero: needs a row swap.
    let a = [[0.0, 2.0, 1.0], [1.0, -1.0, 0.0], [3.0, 0.0, 4.0]];
    let x = [1.5, -2.0, 0.25];
    let b = mat_vec(&a, &x);
    let (got, ratio) = solve(a, b).expect("nonsingular");
    assert!(ratio > 0.0);
    for (g, w) in got.iter().zip(x) {
        assert!((g - w).abs() < 1e-14, "{got:?}");
    }
}

#[test]
fn solve_reports_singular() {
    let a = [[1.0, 2.0], [2.0, 4.0]];
    assert!(solve(a, [1.0, 1.0]).is_none());
}

#[test]
fn spd_scaled_solve_handles_wild_scales() {
    // Diagonal scales 1e-12 .. 1e6 around a well-conditioned core.
    let core = [[2.0, 0.5, 0.1], [0.5, 1.0, 0.3], [0.1, 0.3, 1.5]];
    let s = [1e-6, 1.0, 1e3];
    let w: Matrix<3, 3> =
        core::array::from_fn(|i| core::array::from_fn(|j| core[i][j] * s[i] * s[j]));
    let x = [3.0e5, -2.0, 1.0e-3];
    let d = mat_vec(&w, &x);
    let (got, _) = spd_solve_scaled(&w, &d).expect("spd");
    for (g, want) in got.iter().zip(x) {
        assert!((g - want).abs() <= 1e-12 * want.abs(), "{got:?}");
    }
}

#[test]
fn expm_closed_forms() {
    // Diagonal.
    let a = [[-3.0, 0.0], [0.0, 0.5]];
    let (e, phi) = expm_and_integral(&a, 0.7);
    assert!(close(
        &e,
        &[[libm::exp(-2.1), 0.0], [0.0, libm::exp(0.35)]],
        1e-15
    ));
    let want_phi = [
        [(1.0 - libm::exp(-2.1)) / 3.0, 0.0],
        [0.0, (libm::exp(0.35) - 1.0) / 0.5],
    ];
    assert!(close(&phi, &want_phi, 1e-15));
    // Rotation.
    let w = 2.0 * core::f64::consts::PI * 10e3;
    let a = [[0.0, w], [-w, 0.0]];
    let t = 37e-6;
    let (e, _) = expm_and_integral(&a, t);
    let (s, c) = (libm::sin(w * t), libm::cos(w * t));
    assert!(close(&e, &[[c, s], [-s, c]], 1e-13), "{e:?}");
    // Nilpotent chain (triple integrator): e^{At} = I + At + A²t²/2.
    let a = [[0.0, 1.0, 0.0], [0.0, 0.0, 5.0e5], [0.0, 0.0, 0.0]];
    let t = 1e-5;
    let (e, phi) = expm_and_integral(&a, t);
    let want = [
        [1.0, t, 5.0e5 * t * t / 2.0],
        [0.0, 1.0, 5.0e5 * t],
        [0.0, 0.0, 1.0],
    ];
    assert!(close(&e, &want, 1e-15));
    let want_phi = [
        [t, t * t / 2.0, 5.0e5 * t * t * t / 6.0],
        [0.0, t, 5.0e5 * t * t / 2.0],
        [0.0, 0.0, t],
    ];
    assert!(close(&phi, &want_phi, 1e-15));
}

proptest! {
    /// e^{At} and e^{-At} are inverses (for a badly scaled 3×3 with
    /// galvo-like magnitudes).
    #[test]
    fn expm_inverse_pair(
        k1 in 1e4f64..1e7, k2 in 1.0f64..1e3, k3 in 1e3f64..1e5, b in 1e2f64..1e4,
        t in 1e-7f64..1e-3,
    ) {
        let a = [[0.0, 1.0, 0.0], [0.0, 0.0, k1], [0.0, -k2, -k3]];
        let (e, _) = expm_and_integral(&a, t);
        let (einv, _) = expm_and_integral(&a, -t);
        let prod = mat_mul(&e, &einv);
        // Tolerance scaled by the size of the factors (cancellation).
        let scale = norm_1(&e) * norm_1(&einv);
        for (i, row) in prod.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                prop_assert!((v - want).abs() <= 1e-12 * scale, "{prod:?}");
            }
        }
        let _ = b;
    }

    /// Semigroup: e^{A(s+t)} = e^{As} e^{At}, Φ(s+t) = Φ(s) + e^{As} Φ(t).
    #[test]
    fn expm_semigroup(s in 1e-7f64..5e-4, t in 1e-7f64..5e-4) {
        let a = [[0.0, 1.0, 0.0], [0.0, 0.0, 575_000.0], [0.0, -63.9, -15_556.0]];
        let (es, ps) = expm_and_integral(&a, s);
        let (et, pt) = expm_and_integral(&a, t);
        let (est, pst) = expm_and_integral(&a, s + t);
        prop_assert!(close(&mat_mul(&es, &et), &est, 1e-12));
        prop_assert!(close(&mat_add(&ps, &mat_mul(&es, &pt)), &pst, 1e-12));
    }

    /// solve is the inverse of mat_vec for well-conditioned matrices.
    #[test]
    fn solve_inverts_mat_vec(m in proptest::array::uniform4(proptest::array::uniform4(-1.0f64..1.0)),
                             x in proptest::array::uniform4(-10.0f64..10.0)) {
        // Diagonally dominant → well conditioned.
        let mut a = m;
        for (i, row) in a.iter_mut().enumerate() { row[i] += 5.0; }
        let b = mat_vec(&a, &x);
        let (got, _) = solve(a, b).expect("nonsingular");
        for (g, w) in got.iter().zip(x) { prop_assert!((g - w).abs() < 1e-12); }
    }
}
