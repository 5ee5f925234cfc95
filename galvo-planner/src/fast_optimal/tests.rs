extern crate std;

use super::*;
use crate::bang_bang::OptimalStructure;
use crate::jump::{Method, plan_jump};
use crate::plan::PlanInfo;
use crate::rigid_modes::expm1_f32;
use crate::test_support::{DEG, assert_lands, rigid};
use std::println;

#[test]
fn expm1_matches_f64() {
    let mut worst = 0.0f64;
    let mut z = -30.0f64;
    while z < 0.5 {
        let exact = libm::expm1(f64::from(z as f32));
        let got = f64::from(expm1_f32(z as f32));
        let rel = ((got - exact) / exact).abs();
        if exact != 0.0 {
            worst = worst.max(rel);
        }
        z += 0.0137;
    }
    assert!(worst < 5e-7, "worst relative error {worst}");
}

#[test]
fn sqrt_matches() {
    for x in [1e-6f32, 0.3, 1.0, 8.0, 1234.5, 3e7] {
        let y = sqrt_f32(x);
        assert!((y * y - x).abs() <= 1e-5 * x, "{x}: {y}");
    }
    assert_eq!(sqrt_f32(-1.0), 0.0);
}

#[test]
fn cbrt_matches() {
    for x in [1e-6f32, 0.3, 1.0, 8.0, 1234.5, 3e7] {
        let y = cbrt_f32(x);
        assert!((y * y * y - x).abs() <= 1e-5 * x, "{x}: {y}");
    }
}

#[test]
fn compare_with_reference_planner() {
    for ts in [10e-6, 1e-6, 3.3e-6, 25e-6, 0.2e-6, 100e-6] {
        let d = rigid(ts);
        let mut k = 1e-4;
        while k < 26.0 {
            let fast = plan_jump(&d, 0.0, k * DEG, Method::TimeOptimal, 100_000).expect("fast");
            let slow = crate::optimal::plan_time_optimal(&d, 0.0, k * DEG, 100_000).expect("slow");
            let err = assert_lands(&fast, true, "fast");
            println!(
                "{k:9.4}° fast {} slow {} err {:?} {:?}",
                fast.samples(),
                slow.samples(),
                err,
                fast.info()
            );
            assert!(fast.samples() <= slow.samples());
            k *= 1.5;
        }
    }
}

/// Cost on the M4 is a few hundred instructions per Newton iteration: the
/// whole plan takes a handful (`cargo xtask bench-m4` measures it).
#[test]
fn few_newton_iterations() {
    let d = rigid(10e-6);
    for k in [0.0061, 0.02, 0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 25.0] {
        ITERATIONS.with(|c| c.set(0));
        let p = plan_jump(&d, 0.0, k * DEG, Method::TimeOptimal, 100_000).expect("plan");
        let count = ITERATIONS.with(|c| c.get());
        let (free, fixed) = (count % 100, count / 100);
        println!("{k}°: {} samples, Newton {free} + {fixed}", p.samples());
        assert!(free <= 4 && fixed <= 4, "{k}°: {free} + {fixed} iterations");
    }
}

/// Issue 25: every move from one LSB to the full 4 095-LSB field (every
/// 0.2 %) settles in a bounded number of Newton iterations. A fixed-N
/// solve whose solution a bound (`σ2 ≥ 1`) pinned outside its samples
/// used to run to MAX_NEWTON: 1.336-1.344 LSB took 2 + 26 iterations
/// (10 000 M4 instructions for one axis) before the next N planned it.
#[test]
fn newton_iterations_bounded_from_one_lsb_to_full_field() {
    let d = rigid(10e-6);
    let lsb_deg = 12.5 / 2047.5;
    let mut worst = (0, 0.0);
    let mut lsb = 1.0;
    while lsb <= 4095.0 {
        ITERATIONS.with(|c| c.set(0));
        plan_jump(&d, 0.0, lsb * lsb_deg * DEG, Method::TimeOptimal, 100_000).expect("plan");
        let count = ITERATIONS.with(|c| c.get());
        let total = count % 100 + count / 100;
        if total > worst.0 {
            worst = (total, lsb);
        }
        lsb *= 1.002;
    }
    assert!(
        worst.0 <= 10,
        "{} iterations at {:.3} LSB",
        worst.0,
        worst.1
    );
}

/// The `f32` plan keeps its law in `f32` and derives the rest: its peak
/// voltage (not measured over the inputs) is the largest input, its `f32`
/// inputs are its `f64` ones rounded, and its diagnostics match its
/// inputs (dead-beat: 3 samples; bang-bang: switch samples and last
/// sample), over moves from 0.3 LSB to the full field, both directions.
#[test]
fn f32_law_derives_peak_inputs_and_info() {
    let d = rigid(10e-6);
    let lsb = 12.5 * DEG / 2047.5;
    let (mut dead_beat, mut bang_bang) = (0, 0);
    let mut k = 0.3;
    while k < 4095.0 {
        for (from, sign) in [(0.0, 1.0), (0.2, -1.0), (-0.2, 1.0)] {
            let p = plan_time_optimal_f32(&d, from, from + sign * k * lsb, 1024).expect("plan");
            let u = crate::test_support::inputs(&p);
            let peak = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert_eq!(p.max_abs_u_v(), peak, "{k} LSB: peak");
            p.for_each_input_rev_f32(|j, v| {
                assert_eq!(v, u[j] as f32, "{k} LSB: f32 input {j}");
            });
            let PlanInfo::Optimal(info) = p.info() else {
                panic!("{k} LSB: no optimal info");
            };
            assert!(info.single_precision);
            match info.structure {
                OptimalStructure::DeadBeat => {
                    dead_beat += 1;
                    assert_eq!(p.samples(), 3);
                }
                OptimalStructure::BangBang => {
                    bang_bang += 1;
                    let (s1, s2) = info.switch_samples;
                    assert!(0.0 <= s1 && s1 <= s2 && s2 <= p.samples() as f64);
                    assert_eq!(info.last_sample_v, u[p.samples() - 1], "{k} LSB");
                    let lower = info.samples_lower_bound;
                    assert!(lower <= p.samples() && p.samples() <= lower + 4, "{k} LSB");
                }
                other => panic!("{k} LSB: {other:?}"),
            }
        }
        k *= 1.05;
    }
    assert!(dead_beat > 0 && bang_bang > 0, "{dead_beat} {bang_bang}");
}
