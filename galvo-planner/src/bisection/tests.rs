#![allow(clippy::needless_range_loop)] // reference computations index by sample and state
extern crate std;

use super::*;
use crate::jump::{Method, plan_jump};
use crate::min_energy::plan_min_energy;
use crate::test_support::{DEG, STEPS_DEG, assert_lands, flex, rigid, simulate};

fn bisection_info<const S: usize>(plan: &JumpPlan<S>) -> BisectionInfo {
    match plan.info() {
        PlanInfo::Bisection(i) => i,
        other => panic!("not a bisection plan: {other:?}"),
    }
}

#[test]
fn bisection_lands_within_limits_for_every_step_size() {
    for ts in [10e-6, 1e-6] {
        let d = rigid(ts);
        let df = flex(ts);
        for step in STEPS_DEG {
            for sign in [1.0, -1.0] {
                let to = sign * step * DEG;
                let p =
                    plan_jump(&d, 0.01, 0.01 + to, Method::BISECTION, 100_000).expect("rigid seed");
                assert_lands(&p, true, "rigid seed");
                let p = plan_jump(&df, -0.02, -0.02 + to, Method::BISECTION, 100_000)
                    .expect("flex seed");
                assert_lands(&p, true, "flex seed");
            }
        }
    }
}

/// The flexible target includes φ = θ and zero load speed, so nothing rings
/// after the move: hold U = 0 for 2 ms and the mirror stays put.
#[test]
fn flexible_bisection_leaves_no_residual_vibration() {
    let d = flex(10e-6);
    let plan = plan_jump(&d, 0.0, 10.0 * DEG, Method::BISECTION, 10_000).expect("plan");
    let (states, _) = simulate(&plan);
    let mut z = *states.last().expect("states");
    let mut worst = 0.0f64;
    for _ in 0..200 {
        z = d.step(&z, 0.0);
        worst = worst.max((z[3] - 10.0 * DEG).abs());
    }
    assert!(worst < 1e-6, "mirror moves by {worst} rad after landing");
}

/// Bisection precision: after p halvings the bracket is exactly
/// (Tmax − Tmin)/2^p wide; its lower end is infeasible and its upper end
/// feasible, each checked with a fresh fixed-N minimum-energy solve.
#[test]
fn bisection_precision_matches_p() {
    let d = rigid(10e-6);
    let (z0, z1) = (d.model().rest_state(0.0), d.model().rest_state(2.0 * DEG));
    let mut last_time = f64::INFINITY;
    for p in [0u32, 1, 2, 4, 8, 12, 16] {
        let plan = plan_bisection(
            &d,
            &z0,
            &z1,
            BisectionConfig { p, bracket_s: None },
            100_000,
        )
        .expect("plan");
        let info = bisection_info(&plan);
        let (lo0, hi0) = info.initial_bracket_s;
        let (lo, hi) = info.final_bracket_s;
        let want = (hi0 - lo0) / libm::pow(2.0, f64::from(p));
        // Exact up to the rounding of the bracket ends themselves.
        assert!(
            ((hi - lo) - want).abs() <= 4.0 * f64::EPSILON * hi0,
            "p {p}: width {} vs {want}",
            hi - lo
        );
        assert_eq!(info.halvings, p);
        let n_hi = samples_for(hi, d.ts_s());
        assert_eq!(plan.samples(), n_hi);
        let fits = |n: usize| {
            plan_min_energy(&d, &z0, &z1, n).is_ok_and(|pl| pl.max_abs_u_v() <= d.u_max_v())
        };
        assert!(fits(n_hi), "p {p}: Tmax infeasible");
        if lo > 0.0 {
            assert!(!fits(samples_for(lo, d.ts_s())), "p {p}: Tmin feasible");
        }
        // More halvings never give a longer move.
        assert!(plan.move_time_s() <= last_time + 1e-15);
        last_time = plan.move_time_s();
    }
}

/// Against a brute-force scan of N: the bisection result is within its
/// precision (plus the rounding up to whole samples) of the first feasible N.
#[test]
fn bisection_matches_a_linear_scan() {
    for (ts, step) in [(10e-6, 0.1), (10e-6, 5.0), (10e-6, 20.0), (2e-6, 1.0)] {
        let d = rigid(ts);
        let (z0, z1) = (d.model().rest_state(0.0), d.model().rest_state(step * DEG));
        let scan = (3..5000)
            .find(|&n| plan_min_energy(&d, &z0, &z1, n).is_ok_and(|p| p.max_abs_u_v() <= 24.0))
            .expect("some N is feasible");
        let plan = plan_bisection(&d, &z0, &z1, BisectionConfig::DEFAULT, 100_000).expect("plan");
        let info = bisection_info(&plan);
        let width = info.final_bracket_s.1 - info.final_bracket_s.0;
        let slack = libm::ceil(width / ts) as usize + 1;
        assert!(plan.samples() >= scan, "{step}°: below the scan");
        assert!(
            plan.samples() <= scan + slack,
            "{step}°: {} vs scan {scan} + {slack}",
            plan.samples()
        );
    }
}

#[test]
fn user_bracket_is_validated() {
    let d = rigid(10e-6);
    let (z0, z1) = (d.model().rest_state(0.0), d.model().rest_state(1.0 * DEG));
    let cfg = |lo, hi| BisectionConfig {
        p: 8,
        bracket_s: Some((lo, hi)),
    };
    assert!(matches!(
        plan_bisection(&d, &z0, &z1, cfg(1e-4, 1e-5), 10_000),
        Err(Error::InvalidBracket { .. })
    ));
    // Upper end too short to be feasible.
    assert!(matches!(
        plan_bisection(&d, &z0, &z1, cfg(0.0, 30e-6), 10_000),
        Err(Error::InvalidBracket { .. })
    ));
    assert!(matches!(
        plan_bisection(&d, &z0, &z1, cfg(f64::NAN, 1e-3), 10_000),
        Err(Error::NonFinite { .. })
    ));
    let plan = plan_bisection(&d, &z0, &z1, cfg(0.0, 2e-3), 10_000).expect("feasible bracket");
    let info = bisection_info(&plan);
    assert_eq!(info.initial_bracket_s, (0.0, 2e-3));
    assert!((info.final_bracket_s.1 - info.final_bracket_s.0 - 2e-3 / 256.0).abs() < 1e-15);
    assert_lands(&plan, true, "user bracket");
}

#[test]
fn capacity_and_invalid_requests_are_errors() {
    let d = rigid(10e-6);
    let (z0, z1) = (d.model().rest_state(0.0), d.model().rest_state(20.0 * DEG));
    assert!(matches!(
        plan_bisection(&d, &z0, &z1, BisectionConfig::DEFAULT, 40),
        Err(Error::CapacityExceeded { capacity: 40, .. })
    ));
    let bad = [f64::NAN, 0.0, 0.0];
    assert!(matches!(
        plan_bisection(&d, &bad, &z1, BisectionConfig::DEFAULT, 1000),
        Err(Error::NonFinite { .. })
    ));
    // A tiny voltage limit makes every move longer than the buffer.
    let weak = d
        .model()
        .with_u_max_v(1e-6)
        .and_then(|m| m.discretize(10e-6))
        .expect("valid");
    assert!(matches!(
        plan_bisection(&weak, &z0, &z1, BisectionConfig::DEFAULT, 5000),
        Err(Error::CapacityExceeded { .. })
    ));
    // Zero-length move.
    let p = plan_bisection(&d, &z0, &z0, BisectionConfig::DEFAULT, 0).expect("hold");
    assert_eq!(p.samples(), 0);
}
