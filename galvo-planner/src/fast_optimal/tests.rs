extern crate std;

use super::*;
use crate::jump::{Method, plan_jump};
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

#[test]
fn iteration_counts() {
    let d = rigid(10e-6);
    for k in [0.0061, 0.02, 0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 25.0] {
        ITERATIONS.with(|c| c.set(0));
        let p = plan_jump(&d, 0.0, k * DEG, Method::TimeOptimal, 100_000).expect("plan");
        let crate::jump::PlanInfo::Optimal(i) = p.info() else {
            panic!()
        };
        let md = d.rigid_modes().unwrap().modes;
        let m = (k * DEG * 0.0115 / (10e-6 * 24.0)) as f32;
        let sum = (md[0].ell + md[1].ell).abs();
        let prod = md[0].ell * md[1].ell;
        let n_di = 2.0 * (m * sum / prod).sqrt() + 1.0 / sum;
        let n_tri = cbrt_f32(32.0 * m / prod);
        println!(
            "{k}° n {} it {} cont {:?} n_di {n_di} n_tri {n_tri} 1/sum {}",
            p.samples(),
            ITERATIONS.with(|c| c.get()),
            i.continuous.map(|c| (
                c.time_s / 1e-5,
                (c.time_s - c.switches_s.0) / 1e-5,
                (c.time_s - c.switches_s.1) / 1e-5
            )),
            1.0 / sum
        );
    }
}

#[test]
fn sizes() {
    println!(
        "JumpPlan {} Discrete {} InputLaw {} PlanInfo {} XyJump {}",
        core::mem::size_of::<JumpPlan<3>>(),
        core::mem::size_of::<Discrete<3>>(),
        core::mem::size_of::<InputLaw<3>>(),
        core::mem::size_of::<PlanInfo>(),
        core::mem::size_of::<crate::jump::XyJump<3>>()
    );
}
