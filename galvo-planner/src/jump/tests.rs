extern crate std;

use super::*;
use crate::model::{FlexParams, RigidParams};
use crate::test_support::{DEG, assert_lands, inputs, rigid};
use proptest::prelude::*;

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

proptest! {
    #![proptest_config(crate::test_support::cases(64))]

    /// Far outside the reference galvo (parameters over decades, tiny and
    /// huge voltage limits, sample periods from 0.1 µs to 1 ms, distances
    /// from 1e-9 to 10 rad): every method either returns a plan that lands
    /// (and, for the model-based planners, respects Umax) or a typed
    /// capacity error — no panic, no hang, no wrong plan.
    #[test]
    fn wide_parameter_ranges_give_plans_or_typed_errors(
        kt in log_uniform(1e-4, 1.0), j in log_uniform(1e-10, 1e-5), l in log_uniform(1e-6, 1e-2),
        r in log_uniform(0.1, 100.0), umax in log_uniform(0.01, 1000.0), ts in log_uniform(1e-7, 1e-3),
        dist in log_uniform(1e-9, 10.0), neg: bool,
    ) {
        let p = RigidParams { kt_nm_per_a: kt, j_kg_m2: j, l_h: l, r_ohm: r, u_max_v: umax };
        let Ok(d) = p.model().and_then(|m| m.discretize(ts)) else {
            return Ok(());
        };
        let to = if neg { -dist } else { dist };
        for method in [Method::TimeOptimal, Method::TimeOptimalF64, Method::BISECTION, Method::TCurve, Method::SCurve] {
            match plan_jump(&d, 0.0, to, method, 20_000) {
                Ok(plan) => {
                    let model_based = matches!(method, Method::TimeOptimal | Method::TimeOptimalF64 | Method::Bisection(_));
                    // Landing relative to the move's own scales.
                    let u = inputs(&plan);
                    let mut z = *plan.start_state();
                    for uk in &u {
                        z = d.step(&z, *uk);
                    }
                    let w_scale = umax / kt;
                    let i_scale = umax / r;
                    // The time-optimal planner solves in f32 (the M4F's FPU)
                    // and takes the f64 path where its error estimate exceeds
                    // 1e-3 of the move (the estimate is good to ~2×) or a mode
                    // decays too slowly: θ within 3e-3 of the move, speed and current within 1e-4 of
                    // their scales (on the reference galvo ≤ 1.2e-7 rad and
                    // 4e-4 rad/s, inside the acceptance bounds of 1e-6 rad
                    // and 1e-3 rad/s, A: optimal::tests).
                    let (rel, rel_move) = if method == Method::TimeOptimal { (1e-4, 3e-3) } else { (1e-6, 0.0) };
                    prop_assert!((z[0] - to).abs() <= 1e-6 * dist.max(1e-3) + rel_move * dist, "{method:?}: θ off by {}", z[0] - to);
                    prop_assert!(z[1].abs() <= rel * w_scale, "{method:?}: ω {}", z[1]);
                    prop_assert!(z[2].abs() <= rel * i_scale, "{method:?}: I {}", z[2]);
                    if model_based {
                        prop_assert!(plan.max_abs_u_v() <= umax);
                    }
                }
                Err(Error::CapacityExceeded { .. }) => {}
                Err(e) => prop_assert!(false, "{method:?}: unexpected error {e}"),
            }
        }
    }
}

#[test]
fn xy_jump_plans_both_axes_and_validates_periods() {
    let d = rigid(10e-6);
    let jump = plan_xy_jump(
        &d,
        &d,
        [0.0, 0.0],
        [5.0 * DEG, -DEG],
        Method::TimeOptimal,
        JumpSync::Independent,
        1000,
    )
    .expect("jump");
    assert_lands(&jump.x, true, "x");
    assert_lands(&jump.y, true, "y");
    assert_eq!(jump.samples(), jump.x.samples().max(jump.y.samples()));
    let same = plan_xy_jump(
        &d,
        &d,
        [0.0, 0.0],
        [5.0 * DEG, -DEG],
        Method::TimeOptimal,
        JumpSync::SameDuration,
        1000,
    )
    .expect("jump");
    assert_eq!(same.x.samples(), same.y.samples());
    assert_eq!(same.y.method(), MethodKind::MinEnergy);
    assert_lands(&same.y, true, "stretched y");
    let other = rigid(5e-6);
    assert!(matches!(
        plan_xy_jump(
            &d,
            &other,
            [0.0; 2],
            [0.1; 2],
            Method::BISECTION,
            JumpSync::Independent,
            1000
        ),
        Err(Error::InvalidSamplePeriod { .. })
    ));
}

#[test]
fn plan_accessors_are_consistent() {
    let d = rigid(10e-6);
    let plan = plan_jump(&d, 0.1, 0.2, Method::BISECTION, 1000).expect("plan");
    assert_eq!(plan.method(), MethodKind::Bisection);
    assert_eq!(plan.method().name(), Method::BISECTION.name());
    assert!((plan.move_time_s() - plan.samples() as f64 * 10e-6).abs() < 1e-18);
    let u = inputs(&plan);
    let peak = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert_eq!(plan.max_abs_u_v(), peak);
    // final_state (superposition) agrees with the forward simulation.
    let sim = d.simulate(plan.start_state(), &u, |_, _, _| {});
    for (a, b) in plan.final_state().iter().zip(sim) {
        assert!((a - b).abs() < 1e-9);
    }
    let mut short = [0.0; 3];
    assert!(matches!(
        plan.write_u_v(&mut short),
        Err(Error::CapacityExceeded { capacity: 3, .. })
    ));
    let flex = FlexParams::REFERENCE
        .model()
        .and_then(|m| m.discretize(10e-6))
        .expect("valid");
    assert_eq!(
        plan_jump(&flex, 0.0, 0.1, Method::TimeOptimal, 100),
        Err(Error::UnsupportedModel)
    );
}

#[test]
fn the_f32_only_xy_jump_is_the_time_optimal_one_or_refused() {
    let d = rigid(10e-6);
    // From one LSB-sized step to the full field, both directions.
    for (x_deg, y_deg) in [(0.001, -0.002), (0.5, 3.0), (-12.5, 7.0), (20.0, -20.0)] {
        let to = [x_deg * DEG, y_deg * DEG];
        let f32_only = plan_xy_jump_f32(&d, &d, [0.0, 0.0], to, 1000).expect("f32 plan");
        let optimal = plan_xy_jump(
            &d,
            &d,
            [0.0, 0.0],
            to,
            Method::TimeOptimal,
            JumpSync::Independent,
            1000,
        )
        .expect("plan");
        assert_eq!(f32_only, optimal, "{x_deg}°, {y_deg}°");
        assert_lands(&f32_only.x, true, "x");
        assert_lands(&f32_only.y, true, "y");
    }
    // Where the f32 modal form does not apply (the flexible model), it
    // refuses instead of falling back to the f64 planner.
    let flex = crate::test_support::flex(10e-6);
    assert_eq!(
        plan_xy_jump_f32(&flex, &flex, [0.0; 2], [DEG, DEG], 1000),
        Err(Error::UnsupportedModel)
    );
    assert!(matches!(
        plan_xy_jump_f32(&d, &rigid(5e-6), [0.0; 2], [0.1; 2], 1000),
        Err(Error::InvalidSamplePeriod { .. })
    ));
    assert!(plan_xy_jump_f32(&d, &d, [f64::NAN, 0.0], [0.1; 2], 1000).is_err());
}
