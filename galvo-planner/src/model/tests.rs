#![allow(clippy::needless_range_loop)] // index-heavy reference computations read better with ranges
extern crate std;
use super::*;
use crate::error::Error;
use crate::linalg::{Matrix, Vector, mat_vec};
use proptest::prelude::*;

fn rigid() -> LinearModel<3> {
    RigidParams::REFERENCE.model().expect("reference is valid")
}
fn flex() -> LinearModel<5> {
    FlexParams::REFERENCE.model().expect("reference is valid")
}

/// Nominal magnitudes of (θ, ω, I, φ, ω_φ) used to make matrix entries
/// dimensionless before comparing them.
const X_NOM: [f64; 5] = [0.1, 1000.0, 10.0, 0.1, 1000.0];

/// max |a_ij − b_ij|·x_j/x_i over all entries.
fn scaled_max_diff<const S: usize>(a: &Matrix<S, S>, b: &Matrix<S, S>) -> f64 {
    let mut worst = 0.0f64;
    for i in 0..S {
        for j in 0..S {
            let d = (a[i][j] - b[i][j]).abs() * X_NOM[j] / X_NOM[i];
            worst = worst.max(d);
        }
    }
    worst
}

fn scaled_vec_diff<const S: usize>(a: &Vector<S>, b: &Vector<S>, u_nom: f64) -> f64 {
    (0..S)
        .map(|i| (a[i] - b[i]).abs() * u_nom / X_NOM[i])
        .fold(0.0, f64::max)
}

/// Closed-form ZOH matrices of the rigid model. With M the (ω, I) block
/// `[[0, Kt/J], [−Kt/L, −R/L]]` and real eigenvalues p1 ≠ p2:
/// `e^{Mt} = ((M − p2)e^{p1 t} − (M − p1)e^{p2 t})/(p1 − p2)` (Sylvester),
/// θ integrates ω, and the unit-step response is
/// `I = (e^{p1 t} − e^{p2 t})/(L(p1 − p2))`, `ω = (Kt/J)∫I`, `θ = ∫ω`.
fn rigid_closed_form(p: &RigidParams, t: f64) -> (Matrix<3, 3>, Vector<3>) {
    let c = p.kt_nm_per_a / p.j_kg_m2;
    let e = p.kt_nm_per_a / p.l_h;
    let alpha = p.r_ohm / p.l_h;
    let disc = alpha * alpha - 4.0 * c * e;
    assert!(disc > 0.0, "closed form written for real poles");
    let p1 = (-alpha + disc.sqrt()) / 2.0;
    let p2 = (-alpha - disc.sqrt()) / 2.0;
    let m = [[0.0, c], [-e, -alpha]];
    let (e1, e2) = ((p1 * t).exp(), (p2 * t).exp());
    // ∫₀ᵗ e^{pτ} dτ
    let (i1, i2) = ((p1 * t).exp_m1() / p1, (p2 * t).exp_m1() / p2);
    let mut ad = [[0.0; 3]; 3];
    ad[0][0] = 1.0;
    for r in 0..2 {
        for col in 0..2 {
            let id = if r == col { 1.0 } else { 0.0 };
            let a1 = m[r][col] - p2 * id;
            let a2 = m[r][col] - p1 * id;
            ad[1 + r][1 + col] = (a1 * e1 - a2 * e2) / (p1 - p2);
            if r == 0 {
                // θ row: first row of ∫ e^{Mτ} dτ.
                ad[0][1 + col] = (a1 * i1 - a2 * i2) / (p1 - p2);
            }
        }
    }
    let k = 1.0 / (p.l_h * (p1 - p2));
    let current = k * (e1 - e2);
    let omega = c * k * (i1 - i2);
    // ∫₀ᵗ (e^{pτ} − 1)/p dτ = (e^{pt} − 1 − pt)/p²
    let th = |q: f64| ((q * t).exp_m1() - q * t) / (q * q);
    let theta = c * k * (th(p1) - th(p2));
    (ad, [theta, omega, current])
}

#[test]
fn rigid_discretisation_matches_closed_form() {
    let p = RigidParams::REFERENCE;
    for ts in [0.5e-6, 1e-6, 10e-6, 37e-6, 200e-6] {
        let d = rigid().discretize(ts).expect("valid");
        let (ad, bd) = rigid_closed_form(&p, ts);
        let ea = scaled_max_diff(d.ad(), &ad);
        let eb = scaled_vec_diff(d.bd(), &bd, 24.0);
        assert!(ea < 1e-13, "Ts {ts}: Ad off by {ea}");
        assert!(eb < 1e-13, "Ts {ts}: Bd off by {eb}");
    }
}

/// Classic RK4 of `ż = Az + Bu` with constant `u` over `t` in `steps` steps.
fn rk4<const S: usize>(
    m: &LinearModel<S>,
    z0: Vector<S>,
    u: f64,
    t: f64,
    steps: usize,
) -> Vector<S> {
    let f = |z: &Vector<S>| -> Vector<S> {
        let mut d = mat_vec(m.a(), z);
        for i in 0..S {
            d[i] += m.b()[i] * u;
        }
        d
    };
    let h = t / steps as f64;
    let mut z = z0;
    for _ in 0..steps {
        let k1 = f(&z);
        let k2 = f(&core::array::from_fn(|i| z[i] + 0.5 * h * k1[i]));
        let k3 = f(&core::array::from_fn(|i| z[i] + 0.5 * h * k2[i]));
        let k4 = f(&core::array::from_fn(|i| z[i] + h * k3[i]));
        z = core::array::from_fn(|i| z[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    z
}

fn check_against_rk4<const S: usize>(m: &LinearModel<S>, ts: f64) {
    let d = m.discretize(ts).expect("valid");
    let steps = 4000;
    let mut ad = [[0.0; S]; S];
    for j in 0..S {
        let mut e = [0.0; S];
        e[j] = 1.0;
        let col = rk4(m, e, 0.0, ts, steps);
        for i in 0..S {
            ad[i][j] = col[i];
        }
    }
    let bd = rk4(m, [0.0; S], 1.0, ts, steps);
    let ea = scaled_max_diff(d.ad(), &ad);
    let eb = scaled_vec_diff(d.bd(), &bd, 24.0);
    assert!(ea < 1e-12, "Ts {ts}: Ad differs from RK4 by {ea}");
    assert!(eb < 1e-12, "Ts {ts}: Bd differs from RK4 by {eb}");
}

#[test]
fn discretisation_matches_fine_rk4() {
    for ts in [1e-6, 10e-6, 30e-6] {
        check_against_rk4(&rigid(), ts);
        check_against_rk4(&flex(), ts);
    }
}

#[test]
fn rest_states_are_equilibria() {
    let d = rigid().discretize(10e-6).expect("valid");
    let z = rigid().rest_state(0.3);
    assert_eq!(z, [0.3, 0.0, 0.0]);
    let next = d.step(&z, 0.0);
    assert!((next[0] - 0.3).abs() < 1e-15 && next[1].abs() < 1e-12 && next[2].abs() < 1e-12);
    let df = flex().discretize(10e-6).expect("valid");
    let z = flex().rest_state(-0.2);
    assert_eq!(z, [-0.2, 0.0, 0.0, -0.2, 0.0]);
    let next = df.step(&z, 0.0);
    for (a, b) in next.iter().zip(z) {
        assert!((a - b).abs() < 1e-12, "{next:?}");
    }
}

#[test]
fn power_matches_repeated_steps() {
    let d = flex().discretize(7e-6).expect("valid");
    let z0 = [0.01, 30.0, 0.5, 0.02, -10.0];
    for q in [0usize, 1, 2, 3, 17, 64, 129] {
        let mut z = z0;
        let mut s = [0.0; 5];
        for _ in 0..q {
            z = d.step(&z, 0.0);
            s = d.step(&s, 1.0);
        }
        let (aq, sq) = d.power(q);
        let zq = mat_vec(&aq, &z0);
        for i in 0..5 {
            assert!(
                (zq[i] - z[i]).abs() <= 1e-12 * (1.0 + z[i].abs()) * X_NOM[i],
                "q {q}"
            );
            assert!(
                (sq[i] - s[i]).abs() <= 1e-12 * (1.0 + s[i].abs()) * X_NOM[i],
                "q {q}"
            );
        }
    }
}

#[test]
fn invalid_parameters_are_typed_errors() {
    let mut p = RigidParams::REFERENCE;
    p.r_ohm = f64::NAN;
    assert_eq!(p.model(), Err(Error::NonFinite { name: "r_ohm" }));
    let mut p = RigidParams::REFERENCE;
    p.j_kg_m2 = 0.0;
    assert!(matches!(
        p.model(),
        Err(Error::NotPositive {
            name: "j_kg_m2",
            ..
        })
    ));
    let mut p = RigidParams::REFERENCE;
    p.kt_nm_per_a = -0.01;
    assert!(matches!(
        p.model(),
        Err(Error::NotPositive {
            name: "kt_nm_per_a",
            ..
        })
    ));
    for u in [0.0, -24.0, f64::NAN, f64::INFINITY] {
        let mut p = RigidParams::REFERENCE;
        p.u_max_v = u;
        assert!(matches!(p.model(), Err(Error::UmaxTooSmall { .. })), "{u}");
    }
    let mut f = FlexParams::REFERENCE;
    f.k_nm_per_rad = 0.0;
    assert!(matches!(
        f.model(),
        Err(Error::NotPositive {
            name: "k_nm_per_rad",
            ..
        })
    ));
    // Ratios that overflow.
    let mut p = RigidParams::REFERENCE;
    p.j_kg_m2 = 1e-320;
    assert!(matches!(p.model(), Err(Error::NonFinite { .. })));
    for ts in [0.0, -1e-5, f64::NAN, f64::INFINITY] {
        assert!(
            matches!(
                rigid().discretize(ts),
                Err(Error::InvalidSamplePeriod { .. })
            ),
            "{ts}"
        );
    }
}

#[test]
fn reference_flex_resonance_is_10_khz() {
    let f = FlexParams::REFERENCE;
    assert!((f.resonance_hz() - 10e3).abs() < 1e-6);
    // K = ω²·Jm·Jl/(Jm + Jl) with ω = 2π·10 kHz, Jm = Jl = 1e-8 kg·m².
    let w = 2.0 * core::f64::consts::PI * 10e3;
    assert!((f.k_nm_per_rad - w * w * 0.5e-8).abs() < 1e-9);
}

// ---- pathological sampling ----------------------------------------------

#[derive(Clone, Copy, Debug)]
struct C(f64, f64);
impl C {
    fn add(self, o: C) -> C {
        C(self.0 + o.0, self.1 + o.1)
    }
    fn sub(self, o: C) -> C {
        C(self.0 - o.0, self.1 - o.1)
    }
    fn mul(self, o: C) -> C {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn div(self, o: C) -> C {
        let d = o.0 * o.0 + o.1 * o.1;
        C(
            (self.0 * o.0 + self.1 * o.1) / d,
            (self.1 * o.0 - self.0 * o.1) / d,
        )
    }
}

/// Roots of the monic polynomial with coefficients `c` (highest first,
/// leading 1 omitted) by Durand–Kerner.
fn roots(c: &[f64]) -> std::vec::Vec<C> {
    let n = c.len();
    let eval = |x: C| {
        let mut acc = C(1.0, 0.0);
        for &ci in c {
            acc = acc.mul(x).add(C(ci, 0.0));
        }
        acc
    };
    let mut r: std::vec::Vec<C> = (0..n)
        .map(|k| {
            let a = 0.4 + 2.0 * core::f64::consts::PI * k as f64 / n as f64;
            C(0.9 * a.cos(), 0.9 * a.sin())
        })
        .collect();
    for _ in 0..2000 {
        for i in 0..n {
            let mut den = C(1.0, 0.0);
            for j in 0..n {
                if i != j {
                    den = den.mul(r[i].sub(r[j]));
                }
            }
            r[i] = r[i].sub(eval(r[i]).div(den));
        }
    }
    r
}

/// The flexible model's characteristic polynomial is `s·q(s)` with
/// `q = L·Jm·Jl·s⁴ + R·Jm·Jl·s³ + (L·K·J + Kt²·Jl)·s² + R·K·J·s + Kt²·K`
/// (J = Jm + Jl), derived by hand from the transfer function. Sampling the
/// lightly damped torsional pair σ ± jω with ω·Ts = π maps both to the same
/// discrete eigenvalue, which a single input cannot steer independently.
#[test]
fn pathological_sampling_is_not_controllable() {
    let f = FlexParams::REFERENCE;
    let (kt, jm, jl, k, l, r) = (
        f.kt_nm_per_a,
        f.jm_kg_m2,
        f.jl_kg_m2,
        f.k_nm_per_rad,
        f.l_h,
        f.r_ohm,
    );
    let j = jm + jl;
    // Scale s = w0·x so the coefficients are O(1).
    let w0 = 2.0 * core::f64::consts::PI * 1e4;
    let q = [
        l * jm * jl,
        r * jm * jl,
        l * k * j + kt * kt * jl,
        r * k * j,
        kt * kt * k,
    ];
    let lead = q[0] * w0.powi(4);
    let c: std::vec::Vec<f64> = (1..5)
        .map(|i| q[i] * w0.powi(4 - i as i32) / lead)
        .collect();
    let rts = roots(&c);
    let torsional = rts
        .iter()
        .copied()
        .fold(C(0.0, 0.0), |best, x| if x.1 > best.1 { x } else { best });
    let w_d = torsional.1 * w0;
    assert!(
        w_d > 0.9 * w0 && w_d < 1.1 * w0,
        "torsional mode near 10 kHz: {w_d}"
    );
    let ts = core::f64::consts::PI / w_d;
    assert_eq!(flex().discretize(ts), Err(Error::NotControllable));
    assert_eq!(
        flex().discretize(2.0 * ts).map(|_| ()),
        Err(Error::NotControllable)
    );
    // A few percent away it is controllable again.
    assert!(flex().discretize(0.95 * ts).is_ok());
    assert!(flex().discretize(1.05 * ts).is_ok());
}

#[test]
fn references_are_controllable_over_the_useful_sample_range() {
    for ts in [0.1e-6, 1e-6, 5e-6, 10e-6, 20e-6, 40e-6] {
        assert!(rigid().discretize(ts).is_ok(), "rigid {ts}");
        assert!(flex().discretize(ts).is_ok(), "flex {ts}");
    }
}

proptest! {
    /// Discretising at k·Ts is the same as k steps of the Ts model
    /// (Ad(kTs) = Ad(Ts)^k, Bd(kTs) = Σ Ad^j Bd).
    #[test]
    fn sampling_is_consistent_across_periods(ts in 0.2e-6f64..20e-6, k in 1usize..40,
                                             scale in 0.5f64..2.0) {
        let mut p = RigidParams::REFERENCE;
        p.j_kg_m2 *= scale;
        p.l_h /= scale;
        let m = p.model().expect("valid");
        let d1 = m.discretize(ts).expect("valid");
        let dk = m.discretize(ts * k as f64).expect("valid");
        let (ak, sk) = d1.power(k);
        prop_assert!(scaled_max_diff(&ak, dk.ad()) < 1e-11);
        prop_assert!(scaled_vec_diff(&sk, dk.bd(), 24.0) < 1e-10);
    }
}
