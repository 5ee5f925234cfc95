extern crate std;

use super::*;
use crate::jump::{Method, plan_jump};
use crate::model::RigidParams;
use crate::test_support::{DEG, STEPS_DEG, assert_lands, flex, rigid, simulate};
use proptest::prelude::*;

fn limits() -> ProfileLimits {
    ProfileLimits {
        v_max_rad_s: 800.0,
        a_max_rad_s2: 2.0e6,
        j_max_rad_s3: 3.0e10,
    }
}

/// Samples the profile on a fine grid and checks continuity, limits
/// (by finite differences, independent of the phase formulas), the end
/// state, and that it is as fast as its limits allow (one of them active).
fn check_profile(p: &Profile) {
    let lim = p.limits;
    let t_end = p.duration_s();
    let n = 20_000;
    let h = t_end / n as f64;
    let d = p.distance_rad;
    let mut prev = p.eval(0.0);
    let mut max_v = 0.0f64;
    let mut max_a = 0.0f64;
    for k in 1..=n {
        let t = k as f64 * h;
        let cur = p.eval(t);
        // Position and speed continuous; finite-difference speed and
        // acceleration within the limits (+ discretisation slack).
        let v_fd = (cur.0 - prev.0) / h;
        let a_fd = (cur.1 - prev.1) / h;
        assert!(v_fd.abs() <= lim.v_max_rad_s * (1.0 + 1e-9), "speed {v_fd}");
        assert!(
            a_fd.abs() <= lim.a_max_rad_s2 * (1.0 + 1e-6),
            "accel {a_fd}"
        );
        if p.kind == ProfileKind::SCurve {
            let j_fd = (cur.2 - prev.2) / h;
            assert!(j_fd.abs() <= lim.j_max_rad_s3 * (1.0 + 1e-6), "jerk {j_fd}");
        }
        max_v = max_v.max(cur.1.abs());
        max_a = max_a.max(cur.2.abs());
        prev = cur;
    }
    let end = p.eval(t_end);
    assert!(
        (end.0 - d).abs() <= 1e-12 * d.abs().max(1e-9),
        "ends at {} not {d}",
        end.0
    );
    assert!(end.1.abs() <= 1e-9 * lim.v_max_rad_s);
    assert_eq!(p.eval(t_end * 1.5), (d, 0.0, 0.0));
    // Time-optimal for its limits: speed limit reached, or acceleration
    // limit reached, or (S-curve) pure jerk phases.
    let v_hit = (max_v - lim.v_max_rad_s).abs() <= 1e-9 * lim.v_max_rad_s;
    let a_hit = (max_a - lim.a_max_rad_s2).abs() <= 1e-6 * lim.a_max_rad_s2;
    let pure_jerk = p.kind == ProfileKind::SCurve && (p.t_accel_s - 2.0 * p.t_jerk_s).abs() < 1e-15;
    assert!(v_hit || a_hit || pure_jerk, "no limit active: {p:?}");
}

#[test]
fn trapezoid_has_the_textbook_duration() {
    let lim = limits();
    let (v, a) = (lim.v_max_rad_s, lim.a_max_rad_s2);
    for d in [1e-5, 1e-3, 0.1, 0.3, 1.0] {
        let p = Profile::new(ProfileKind::Trapezoid, d, lim).expect("valid");
        let want = if d >= v * v / a {
            d / v + v / a
        } else {
            2.0 * (d / a).sqrt()
        };
        assert!((p.duration_s() - want).abs() < 1e-15 + 1e-12 * want, "{d}");
        check_profile(&p);
        check_profile(&Profile::new(ProfileKind::Trapezoid, -d, lim).expect("valid"));
    }
}

#[test]
fn s_curve_covers_all_three_cases() {
    let lim = limits();
    // Pure jerk (tiny), acceleration-limited, and speed-limited moves.
    for d in [1e-7, 1e-5, 1e-3, 0.05, 0.5, 2.0] {
        let p = Profile::new(ProfileKind::SCurve, d, lim).expect("valid");
        check_profile(&p);
        check_profile(&Profile::new(ProfileKind::SCurve, -d, lim).expect("valid"));
    }
    // Pure-jerk closed form: D = 2·j·Tj³ → T = 4·Tj.
    let d = 1e-7;
    let p = Profile::new(ProfileKind::SCurve, d, lim).expect("valid");
    let tj = (d / (2.0 * lim.j_max_rad_s3)).cbrt();
    assert!((p.duration_s() - 4.0 * tj).abs() < 1e-12 * tj);
}

#[test]
fn limits_from_the_model() {
    let m = RigidParams::REFERENCE.model().expect("valid");
    let dr = m.drive();
    let t = ProfileLimits::from_drive(ProfileKind::Trapezoid, dr, 24.0);
    // Half the no-load speed Umax/Kt, half the stall acceleration Kt·Umax/(R·J).
    assert!((t.v_max_rad_s - 0.5 * 24.0 / 0.0115).abs() < 1e-9);
    assert!((t.a_max_rad_s2 - 0.5 * 0.0115 * 24.0 / (2.8 * 2.0e-8)).abs() < 1e-3);
    assert!(t.j_max_rad_s3.is_infinite());
    let s = ProfileLimits::from_drive(ProfileKind::SCurve, dr, 24.0);
    // Each voltage term at its limit uses Umax/3.
    let kt = 0.0115;
    assert!((kt * s.v_max_rad_s - 8.0).abs() < 1e-12);
    assert!((2.8 * 2.0e-8 / kt * s.a_max_rad_s2 - 8.0).abs() < 1e-9);
    assert!((180e-6 * 2.0e-8 / kt * s.j_max_rad_s3 - 8.0).abs() < 1e-9);
}

/// The S-curve's continuous inverse-dynamics voltage never exceeds Umax
/// (the thirds rule), checked on a fine grid.
#[test]
fn s_curve_voltage_stays_below_umax() {
    let m = RigidParams::REFERENCE.model().expect("valid");
    let lim = ProfileLimits::from_drive(ProfileKind::SCurve, m.drive(), 24.0);
    for step in STEPS_DEG {
        let p = Profile::new(ProfileKind::SCurve, step * DEG, lim).expect("valid");
        let n = 5000;
        for k in 0..=n {
            let u = p.voltage_v(m.drive(), p.duration_s() * k as f64 / n as f64);
            assert!(u.abs() <= 24.0 * (1.0 + 1e-12), "{step}°: {u} V");
        }
    }
}

/// The per-sample average equals the quadrature of the continuous voltage
/// (plus, for the trapezoid, the L·J/Kt·Δa impulses inside the sample).
#[test]
fn sample_average_is_the_integral_of_the_voltage() {
    let m = RigidParams::REFERENCE.model().expect("valid");
    let dr = m.drive();
    for kind in [ProfileKind::SCurve, ProfileKind::Trapezoid] {
        let lim = ProfileLimits::from_drive(kind, dr, 24.0);
        let p = Profile::new(kind, 3.0 * DEG, lim).expect("valid");
        let ts = 10e-6;
        let n = (p.duration_s() / ts) as usize + 1;
        for k in 0..n {
            let (t0, t1) = (k as f64 * ts, (k + 1) as f64 * ts);
            // Midpoint rule on 20000 panels: the voltage jumps where the
            // jerk does, which bounds the quadrature error by
            // jump·h/Ts ≈ 8 V / 20000.
            let panels = 20_000;
            let hh = ts / panels as f64;
            let acc: f64 = (0..panels)
                .map(|i| p.voltage_v(dr, t0 + (i as f64 + 0.5) * hh))
                .sum();
            let mut avg = acc * hh / ts;
            if kind == ProfileKind::Trapezoid {
                // Acceleration steps at 0, ta, ta+tc, T within [t0, t1).
                let ta = p.t_accel_s;
                let tc = p.t_cruise_s;
                let a = p.a_peak_rad_s2;
                let steps = [(0.0, a), (ta, -a), (ta + tc, -a), (ta + tc + ta, a)];
                for (t, da) in steps {
                    if t >= t0 && t < t1 {
                        avg += dr.l_h * dr.j_kg_m2 / dr.kt_nm_per_a * da / ts;
                    }
                }
            }
            let got = p.average_u_v(dr, ts, k);
            assert!(
                (got - avg).abs() < 1e-3,
                "{kind:?} sample {k}: {got} vs {avg}"
            );
        }
    }
}

#[test]
fn baseline_plans_land_and_report_their_voltage() {
    for ts in [10e-6, 1e-6] {
        let d = rigid(ts);
        let df = flex(ts);
        for step in STEPS_DEG {
            let to = step * DEG;
            let t = plan_jump(&d, 0.0, to, Method::TCurve, 100_000).expect("tcurve");
            assert_lands(&t, false, "tcurve");
            // Ignoring the inductance costs a lot of voltage.
            assert!(
                t.max_abs_u_v() > 24.0,
                "{step}°: T-curve peak {}",
                t.max_abs_u_v()
            );
            let s = plan_jump(&d, 0.0, -to, Method::SCurve, 100_000).expect("scurve");
            assert_lands(&s, true, "scurve");
            let s = plan_jump(&df, 0.0, to, Method::SCurve, 100_000).expect("flex scurve");
            assert_lands(&s, false, "flex scurve");
            let t = plan_jump(&df, 0.0, -to, Method::TCurve, 100_000).expect("flex tcurve");
            assert_lands(&t, false, "flex tcurve");
        }
    }
}

/// The sampled inverse dynamics really follows the profile: the ZOH
/// simulation of the plan stays close to θ(k·Ts) of the profile (the
/// landing correction is small).
#[test]
fn zoh_simulation_follows_the_profile() {
    let d = rigid(10e-6);
    // The T-curve demands current steps the coil cannot make within a
    // sample, so it follows less closely.
    for (method, kind, tol) in [
        (Method::SCurve, ProfileKind::SCurve, 1e-3),
        (Method::TCurve, ProfileKind::Trapezoid, 1e-2),
    ] {
        let plan = plan_jump(&d, 0.0, 5.0 * DEG, method, 10_000).expect("plan");
        let lim = ProfileLimits::from_drive(kind, d.model().drive(), 24.0);
        let prof = Profile::new(kind, 5.0 * DEG, lim).expect("valid");
        let (states, _) = simulate(&plan);
        let worst = states
            .iter()
            .enumerate()
            .map(|(k, z)| (z[0] - prof.eval(k as f64 * 10e-6).0).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < tol * 5.0 * DEG,
            "{kind:?}: tracking error {worst} rad"
        );
    }
}

#[test]
fn invalid_limits_are_errors() {
    let mut l = limits();
    l.a_max_rad_s2 = 0.0;
    assert!(matches!(
        Profile::new(ProfileKind::Trapezoid, 0.1, l),
        Err(Error::NotPositive { .. })
    ));
    let mut l = limits();
    l.j_max_rad_s3 = f64::NAN;
    assert!(Profile::new(ProfileKind::SCurve, 0.1, l).is_err());
    assert!(matches!(
        Profile::new(ProfileKind::SCurve, f64::NAN, limits()),
        Err(Error::NonFinite { .. })
    ));
    let d = rigid(10e-6);
    assert!(matches!(
        plan_profile(&d, 0.0, 0.3, ProfileKind::SCurve, None, 20),
        Err(Error::CapacityExceeded { capacity: 20, .. })
    ));
}

proptest! {
    /// Mirror symmetry: the profile for −D is the negation of +D.
    #[test]
    fn negative_distance_mirrors(d in 1e-6f64..1.0) {
        for kind in [ProfileKind::Trapezoid, ProfileKind::SCurve] {
            let p = Profile::new(kind, d, limits()).expect("valid");
            let q = Profile::new(kind, -d, limits()).expect("valid");
            for k in 0..=50 {
                let t = p.duration_s() * k as f64 / 50.0;
                let (a, b) = (p.eval(t), q.eval(t));
                prop_assert_eq!((a.0, a.1, a.2), (-b.0, -b.1, -b.2));
            }
        }
    }
}
