//! Helpers shared by the unit tests (compiled for tests only).
extern crate std;

use std::vec::Vec;

use crate::linalg::Vector;
use crate::model::{Discrete, FlexParams, RigidParams};
use crate::plan::JumpPlan;

/// Property-test configuration with `default` cases, or `PROPTEST_CASES`
/// when set (for stress runs).
pub fn cases(default: u32) -> proptest::test_runner::Config {
    let n = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default);
    proptest::test_runner::Config {
        cases: n,
        ..proptest::test_runner::Config::default()
    }
}

/// Degrees → radians.
pub const DEG: f64 = core::f64::consts::PI / 180.0;
/// The step sizes of the acceptance criteria, mechanical degrees.
pub const STEPS_DEG: [f64; 9] = [0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0];

pub fn rigid(ts_s: f64) -> Discrete<3> {
    RigidParams::REFERENCE
        .model()
        .and_then(|m| m.discretize(ts_s))
        .expect("reference rigid model")
}

pub fn flex(ts_s: f64) -> Discrete<5> {
    FlexParams::REFERENCE
        .model()
        .and_then(|m| m.discretize(ts_s))
        .expect("reference flexible model")
}

/// The plan's voltages in sample order.
pub fn inputs<const S: usize>(plan: &JumpPlan<S>) -> Vec<f64> {
    let mut u = std::vec![f64::NAN; plan.samples()];
    let n = plan.write_u_v(&mut u).expect("buffer sized to the plan");
    assert_eq!(n, plan.samples());
    assert!(u.iter().all(|v| v.is_finite()), "every sample written");
    u
}

/// Forward ZOH simulation of the plan's voltages: states k = 0..=N.
pub fn simulate<const S: usize>(plan: &JumpPlan<S>) -> (Vec<Vector<S>>, Vec<f64>) {
    let u = inputs(plan);
    let mut states = Vec::with_capacity(u.len() + 1);
    plan.discrete()
        .simulate(plan.start_state(), &u, |_, z, _| states.push(*z));
    (states, u)
}

/// Acceptance landing bounds: angles 1e-6 rad, speeds and current 1e-3.
pub fn landing_bounds<const S: usize>() -> Vector<S> {
    core::array::from_fn(|i| match i {
        0 | 3 => 1e-6,
        _ => 1e-3,
    })
}

/// Simulates the plan and checks the acceptance criteria: lands on the
/// target within [`landing_bounds`] and (if `check_limit`) never exceeds
/// Umax. Returns the final state error.
pub fn assert_lands<const S: usize>(
    plan: &JumpPlan<S>,
    check_limit: bool,
    what: &str,
) -> Vector<S> {
    let (states, u) = simulate(plan);
    let last = states.last().expect("at least the start state");
    let err: Vector<S> = core::array::from_fn(|i| (last[i] - plan.target_state()[i]).abs());
    let bounds = landing_bounds::<S>();
    for i in 0..S {
        assert!(
            err[i] <= bounds[i],
            "{what}: state {i} misses by {} ({err:?})",
            err[i]
        );
    }
    if check_limit {
        let umax = plan.discrete().u_max_v();
        let peak = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(peak <= umax, "{what}: peak {peak} V > Umax {umax} V");
    }
    err
}
