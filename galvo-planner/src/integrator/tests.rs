extern crate std;

use super::*;
use crate::error::Error;
use crate::jump::{JumpSync, Method, plan_jump, plan_xy_jump};
use crate::plan::JumpPlan;
use crate::test_support::{DEG, flex, rigid, simulate};
use proptest::prelude::*;
use std::vec::Vec;

/// Runs the plan through a fresh integrator and the f64 ZOH simulation and
/// returns the largest θ difference over the move.
fn tracking_error<const S: usize>(plan: &JumpPlan<S>) -> f64 {
    let mut st: Integrator<S, 4096> =
        Integrator::new(plan.discrete(), plan.start_state()[0]).expect("integrator");
    st.queue(plan).expect("queue");
    let (states, _) = simulate(plan);
    let mut worst = 0.0f64;
    for z in states.iter().skip(1) {
        let theta = st.step();
        worst = worst.max((f64::from(theta) - z[0]).abs());
    }
    assert!(st.is_idle());
    // Snapped to the exact target (as f32).
    assert_eq!(st.position_rad(), plan.target_state()[0] as f32);
    worst
}

#[test]
fn f32_integrator_tracks_the_f64_plan() {
    for ts in [10e-6, 1e-6] {
        let d = rigid(ts);
        for method in [
            Method::TimeOptimal,
            Method::BISECTION,
            Method::SCurve,
            Method::TCurve,
        ] {
            for (from, to) in [(-10.0, 10.0), (3.0, 3.05), (12.0, -8.0)] {
                let plan = plan_jump(&d, from * DEG, to * DEG, method, 4096).expect("plan");
                let e = tracking_error(&plan);
                assert!(e <= 1e-6, "Ts {ts} {method:?} {from}→{to}: {e} rad");
            }
        }
        let df = flex(ts);
        let plan = plan_jump(&df, -10.0 * DEG, 10.0 * DEG, Method::BISECTION, 4096).expect("plan");
        let e = tracking_error(&plan);
        assert!(e <= 1e-6, "flex Ts {ts}: {e} rad");
    }
}

#[test]
fn queue_while_moving_then_hold() {
    let d = rigid(10e-6);
    let mut st: Integrator<3, 256> = Integrator::new(&d, 0.0).expect("integrator");
    let a = plan_jump(&d, 0.0, 5.0 * DEG, Method::TimeOptimal, 256).expect("a");
    st.queue(&a).expect("queue a");
    assert!(!st.is_idle());
    let mut out = Vec::new();
    for _ in 0..a.samples() / 2 {
        out.push(st.step());
    }
    // Queue the next move from where the queue ends, mid-move.
    assert_eq!(st.end_position_rad(), 5.0 * DEG);
    let b = plan_jump(
        &d,
        st.end_position_rad(),
        -2.0 * DEG,
        Method::BISECTION,
        256,
    )
    .expect("b");
    st.queue(&b).expect("queue b");
    assert_eq!(st.queued_moves(), 2);
    while !st.is_idle() {
        out.push(st.step());
    }
    assert_eq!(out.len(), a.samples() + b.samples());
    // The sample at the junction is exactly a's target.
    assert_eq!(out[a.samples() - 1], (5.0 * DEG) as f32);
    assert_eq!(*out.last().expect("samples"), (-2.0 * DEG) as f32);
    // Idle: holds without drifting.
    for _ in 0..1000 {
        assert_eq!(st.step(), (-2.0 * DEG) as f32);
    }
    assert_eq!(st.state(), &[(-2.0 * DEG) as f32, 0.0, 0.0]);
}

#[test]
fn fill_equals_stepping() {
    let d = rigid(10e-6);
    let plan = plan_jump(&d, 0.0, 7.0 * DEG, Method::BISECTION, 512).expect("plan");
    let mut a: Integrator<3, 512> = Integrator::new(&d, 0.0).expect("integrator");
    a.queue(&plan).expect("queue");
    let mut b = a.clone();
    let mut block = [0.0f32; 32];
    let mut filled = Vec::new();
    for _ in 0..4 {
        a.fill(&mut block);
        filled.extend_from_slice(&block);
    }
    let stepped: Vec<f32> = (0..128).map(|_| b.step()).collect();
    assert_eq!(filled, stepped);
}

/// Runs of any length, across move ends (two moves queued back to back)
/// and into the idle hold, give the stepped angles bit for bit, for both
/// axes of an [`XyIntegrator`].
#[test]
fn fill_runs_equal_stepping_across_moves() {
    let d = rigid(10e-6);
    let first = plan_xy_jump(
        &d,
        &d,
        [0.0, 0.0],
        [3.0 * DEG, -DEG],
        Method::TimeOptimal,
        JumpSync::Independent,
        512,
    )
    .expect("plan");
    let second = plan_xy_jump(
        &d,
        &d,
        [3.0 * DEG, -DEG],
        [-4.0 * DEG, 2.5 * DEG],
        Method::TimeOptimal,
        JumpSync::Independent,
        512,
    )
    .expect("plan");
    for block in [1usize, 3, 7, 32, 100] {
        let mut a: XyIntegrator<3, 1024> =
            XyIntegrator::new(&d, &d, [0.0, 0.0]).expect("integrator");
        a.queue_jump(&first).expect("queue");
        a.queue_jump(&second).expect("queue");
        let mut b = a.clone();
        let total = first.samples() + second.samples() + 20;
        let mut filled = Vec::new();
        let mut buf = [[0.0f32; 2]; 100];
        while filled.len() < total {
            a.fill(&mut buf[..block]);
            filled.extend_from_slice(&buf[..block]);
        }
        let stepped: Vec<[f32; 2]> = (0..filled.len()).map(|_| b.step()).collect();
        assert_eq!(filled, stepped, "block {block}");
        assert!(a.is_idle());
        assert_eq!(a.x.state(), b.x.state());
    }
}

#[test]
fn queue_errors() {
    let d = rigid(10e-6);
    let mut st: Integrator<3, 40, 2> = Integrator::new(&d, 0.0).expect("integrator");
    // Does not start where the queue ends.
    let off = plan_jump(&d, 1.0 * DEG, 2.0 * DEG, Method::BISECTION, 64).expect("plan");
    assert_eq!(st.queue(&off), Err(Error::DiscontinuousMove));
    // Too many samples for the ring.
    let long = plan_jump(&d, 0.0, 20.0 * DEG, Method::TimeOptimal, 1000).expect("plan");
    assert!(long.samples() > 40);
    assert_eq!(st.queue(&long), Err(Error::QueueFull));
    // Move slots: Q = 2.
    let m1 = plan_jump(&d, 0.0, 0.1 * DEG, Method::TimeOptimal, 64).expect("plan");
    let m2 = plan_jump(&d, 0.1 * DEG, 0.2 * DEG, Method::TimeOptimal, 64).expect("plan");
    let m3 = plan_jump(&d, 0.2 * DEG, 0.3 * DEG, Method::TimeOptimal, 64).expect("plan");
    st.queue(&m1).expect("m1");
    st.queue(&m2).expect("m2");
    assert_eq!(st.queue(&m3), Err(Error::QueueFull));
    // Another model.
    let other = rigid(5e-6);
    let p = plan_jump(&other, 0.2 * DEG, 0.3 * DEG, Method::TimeOptimal, 64).expect("plan");
    assert_eq!(st.check_queue(&p), Err(Error::ModelMismatch));
    // Zero-length moves are accepted and change nothing.
    let hold = plan_jump(&d, 0.2 * DEG, 0.2 * DEG, Method::BISECTION, 0).expect("hold");
    st.queue(&hold).expect("hold");
    assert_eq!(st.queued_moves(), 2);
    assert!(Integrator::<3, 8>::new(&d, f64::NAN).is_err());
}

#[test]
fn clear_pending_keeps_the_running_move() {
    let d = rigid(10e-6);
    let mut st: Integrator<3, 512> = Integrator::new(&d, 0.0).expect("integrator");
    let a = plan_jump(&d, 0.0, 3.0 * DEG, Method::TimeOptimal, 512).expect("a");
    let b = plan_jump(&d, 3.0 * DEG, 6.0 * DEG, Method::TimeOptimal, 512).expect("b");
    st.queue(&a).expect("a");
    st.queue(&b).expect("b");
    st.step();
    assert_eq!(st.clear_pending(), 1);
    assert_eq!(st.end_position_rad(), 3.0 * DEG);
    assert_eq!(st.remaining_samples(), a.samples() - 1);
    while !st.is_idle() {
        st.step();
    }
    assert_eq!(st.position_rad(), (3.0 * DEG) as f32);
}

#[test]
fn xy_jumps() {
    let d = rigid(10e-6);
    let from = [0.0, 0.0];
    let to = [10.0 * DEG, 0.5 * DEG];
    for sync in [JumpSync::Independent, JumpSync::SameDuration] {
        let jump = plan_xy_jump(&d, &d, from, to, Method::TimeOptimal, sync, 1024).expect("jump");
        let mut xy: XyIntegrator<3, 1024> = XyIntegrator::new(&d, &d, from).expect("xy");
        xy.queue_jump(&jump).expect("queue");
        let mut n = 0;
        let mut y_done_at = None;
        while !xy.is_idle() {
            xy.step();
            n += 1;
            if y_done_at.is_none() && xy.y.is_idle() {
                y_done_at = Some(n);
            }
        }
        assert_eq!(n, jump.samples());
        assert_eq!(xy.step(), [to[0] as f32, to[1] as f32]);
        match sync {
            JumpSync::Independent => assert!(y_done_at < Some(n)),
            JumpSync::SameDuration => {
                assert_eq!(y_done_at, Some(n));
                assert!(jump.y.max_abs_u_v() < 24.0);
            }
        }
    }
    // Atomic: if Y does not fit, X is not queued either.
    let mut xy: XyIntegrator<3, 40> = XyIntegrator::new(&d, &d, from).expect("xy");
    let jump = plan_xy_jump(
        &d,
        &d,
        from,
        [0.1 * DEG, 20.0 * DEG],
        Method::TimeOptimal,
        JumpSync::Independent,
        1024,
    )
    .expect("jump");
    assert_eq!(xy.queue_jump(&jump), Err(Error::QueueFull));
    assert!(xy.x.is_idle());
}

#[test]
fn hold_at_reseats_an_idle_integrator_only() {
    let d = rigid(10e-6);
    let mut st: Integrator<3, 256> = Integrator::new(&d, 0.0).expect("integrator");
    st.hold_at(0.1).expect("idle");
    assert_eq!(st.state(), &[0.1f32, 0.0, 0.0]);
    assert_eq!(st.step(), 0.1f32);
    let plan = plan_jump(&d, 0.1, 0.2, Method::TimeOptimal, 256).expect("plan");
    st.queue(&plan).expect("queue from the new position");
    assert_eq!(st.hold_at(0.5), Err(Error::IntegratorBusy));
    assert!(matches!(st.hold_at(f64::NAN), Err(Error::NonFinite { .. })));
    let df = flex(10e-6);
    let mut sf: Integrator<5, 64> = Integrator::new(&df, 0.0).expect("integrator");
    sf.hold_at(-0.2).expect("idle");
    assert_eq!(sf.end_state(), &[-0.2, 0.0, 0.0, -0.2, 0.0]);
    let mut xy: XyIntegrator<3, 64> = XyIntegrator::new(&d, &d, [0.0, 0.0]).expect("xy");
    xy.hold_at([0.01, -0.02]).expect("idle");
    assert_eq!(xy.end_position_rad(), [0.01, -0.02]);
}

proptest! {
    #![proptest_config(crate::test_support::cases(16))]

    /// A long sequence of random moves: every move ends exactly on its
    /// target and the f32 state never drifts from the f64 plan.
    #[test]
    fn no_drift_across_many_moves(targets in proptest::collection::vec(-12.0f64..12.0, 1..30)) {
        let d = rigid(10e-6);
        let mut st: Integrator<3, 256> = Integrator::new(&d, 0.0).expect("integrator");
        for t in targets {
            let plan = plan_jump(&d, st.end_position_rad(), t * DEG, Method::TimeOptimal, 256).expect("plan");
            st.queue(&plan).expect("queue");
            let (states, _) = simulate(&plan);
            for z in states.iter().skip(1) {
                let th = st.step();
                prop_assert!((f64::from(th) - z[0]).abs() <= 1e-6);
            }
            prop_assert!(st.is_idle());
            prop_assert_eq!(st.position_rad(), (t * DEG) as f32);
        }
    }
}

/// The `f32` inputs the integrator queues are the plan's `f64` inputs
/// rounded, for bang-bang plans of many lengths (switches anywhere) and
/// the other laws.
#[test]
fn f32_inputs_are_the_rounded_f64_inputs() {
    let d = rigid(10e-6);
    let mut plans = Vec::new();
    for k in 1..40 {
        let to = f64::from(k) * 0.37 * DEG - 6.0 * DEG;
        plans.push(plan_jump(&d, 0.0, to, Method::TimeOptimal, 1024).expect("plan"));
    }
    plans.push(plan_jump(&d, 0.0, 2.0 * DEG, Method::BISECTION, 1024).expect("plan"));
    for plan in &plans {
        let mut wide = Vec::new();
        plan.for_each_input_rev(|k, u| wide.push((k, u as f32)));
        let mut narrow = Vec::new();
        plan.for_each_input_rev_f32(|k, u| narrow.push((k, u)));
        assert_eq!(wide, narrow);
    }
}

/// A jump's angles computed ahead (`plan_angles`, `blocks::jump_angles`)
/// are what the integrator steps for it, bit for bit; an integrator that
/// skips the jump's samples lands where stepping lands.
#[test]
fn angles_ahead_equal_stepping_and_skipping_lands() {
    let d = rigid(10e-6);
    let from = [2.0 * DEG, -3.0 * DEG];
    for to in [
        [-6.0 * DEG, 5.0 * DEG],
        [2.0 * DEG, 4.0 * DEG],
        [9.0 * DEG, -3.5 * DEG],
    ] {
        let jump = plan_xy_jump(
            &d,
            &d,
            from,
            to,
            Method::TimeOptimal,
            JumpSync::Independent,
            1024,
        )
        .expect("plan");
        let mut stepped: crate::blocks::LoopIntegrator =
            XyIntegrator::new(&d, &d, from).expect("integrator");
        let mut x = [0.0f32; crate::blocks::PRECOMPUTED_JUMP];
        let mut y = [0.0f32; crate::blocks::PRECOMPUTED_JUMP];
        let n = crate::blocks::jump_angles(&stepped, &jump, &mut x, &mut y).expect("angles");
        assert_eq!(n, jump.samples());
        let ahead: Vec<[f32; 2]> = x.iter().zip(&y).map(|(x, y)| [*x, *y]).collect();
        let mut skipped = stepped.clone();
        stepped.queue_jump(&jump).expect("queue");
        skipped.queue_jump_skipped(&jump).expect("queue");
        let steps: Vec<[f32; 2]> = (0..n).map(|_| stepped.step()).collect();
        assert_eq!(&ahead[..n], &steps[..]);
        skipped.skip(n / 2);
        assert!(!skipped.is_idle());
        skipped.skip(n - n / 2);
        assert!(skipped.is_idle());
        assert_eq!(skipped.x.state(), stepped.x.state());
        assert_eq!(skipped.y.state(), stepped.y.state());
        assert_eq!(skipped.step(), stepped.step());
    }
}

#[test]
fn reset_in_place_equals_a_new_integrator() {
    let slow = rigid(20e-6);
    let fast = rigid(10e-6);
    let from = [1.0 * DEG, -2.0 * DEG];
    let to = [8.0 * DEG, 3.0 * DEG];
    let plan = |d| {
        plan_xy_jump(
            d,
            d,
            from,
            to,
            Method::TimeOptimal,
            JumpSync::Independent,
            1024,
        )
    };
    // A busy integrator of another model, reset mid-jump.
    let mut reset: XyIntegrator<3, 1024> = XyIntegrator::new(&slow, &slow, [0.0, 0.0]).expect("xy");
    let other = plan_xy_jump(
        &slow,
        &slow,
        [0.0, 0.0],
        to,
        Method::TimeOptimal,
        JumpSync::Independent,
        1024,
    )
    .expect("jump");
    reset.queue_jump(&other).expect("queue");
    reset.step();
    // A refused reset changes nothing.
    assert!(reset.reset(&fast, &fast, [f64::NAN, 0.0]).is_err());
    assert!(!reset.is_idle());
    reset.reset(&fast, &fast, from).expect("reset");
    assert!(reset.is_idle());
    let mut fresh: XyIntegrator<3, 1024> = XyIntegrator::new(&fast, &fast, from).expect("xy");
    let jump = plan(&fast).expect("jump");
    reset.queue_jump(&jump).expect("queue");
    fresh.queue_jump(&jump).expect("queue");
    for _ in 0..jump.samples() + 3 {
        assert_eq!(reset.step(), fresh.step());
    }
    assert_eq!(reset.x.end_state(), fresh.x.end_state());
}
