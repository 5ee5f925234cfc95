//! Jump planning per method over 0.1°–20° (one axis, mechanical), and
//! two-axis jumps as the loop plans them.

use core::hint::black_box;

use galvo_planner::{JumpSync, Method, plan_jump, plan_xy_jump};
use kinematics_core::{Galvo, PointMm};

use crate::harness::{Bench, CAPACITY, Name, deg, reference_plant_at_10us, window};

/// Jump planning per method over 0.1°–20° (one axis, mechanical), and
/// two-axis jumps as the loop plans them.
pub fn planning(b: &mut Bench) {
    let disc = match reference_plant_at_10us() {
        Ok(d) => d,
        Err(e) => return b.fail("plan.setup", e),
    };
    let mut name = Name::new();
    for (method_id, method) in [
        ("plan.optimal", Method::TimeOptimal),
        ("plan.seed", Method::BISECTION),
        ("plan.tcurve", Method::TCurve),
        ("plan.scurve", Method::SCurve),
    ] {
        for (amp_id, amp_deg) in [
            (".0.1deg", 0.1),
            (".1deg", 1.0),
            (".5deg", 5.0),
            (".20deg", 20.0),
        ] {
            name.set(method_id, amp_id);
            let mut result = Ok(());
            let ticks = window(|| {
                result = plan_jump(&disc, 0.0, deg(amp_deg), method, CAPACITY).map(|p| {
                    black_box(&p);
                });
            });
            match result {
                Ok(()) => b.report(name.as_str(), ticks, 1),
                Err(e) => b.fail(name.as_str(), e),
            }
        }
    }
    // Two axes, as the loop plans them (both axes, time-optimal).
    let galvo = Galvo::<f64>::default();
    let lsb = 1.0 / galvo.dac_x.codes_per_rad;
    let angles = |x_mm: f64, y_mm: f64| {
        galvo
            .geometry
            .ik(PointMm::new(x_mm, y_mm))
            .map(|a| [a.x_rad, a.y_rad])
    };
    let cases = [
        ("plan.xy.optimal.1lsb", Ok([0.0, 0.0]), Ok([lsb, lsb])),
        (
            "plan.xy.optimal.160mm",
            angles(-80.0, -80.0),
            angles(80.0, 80.0),
        ),
    ];
    for (id, from, to) in cases {
        let (Ok(from), Ok(to)) = (from, to) else {
            b.fail(id, "ik");
            continue;
        };
        let mut result = Ok(());
        let ticks = window(|| {
            result = plan_xy_jump(
                &disc,
                &disc,
                from,
                to,
                Method::TimeOptimal,
                JumpSync::Independent,
                CAPACITY,
            )
            .map(|p| {
                black_box(&p);
            });
        });
        match result {
            Ok(()) => b.report(id, ticks, 1),
            Err(e) => b.fail(id, e),
        }
    }
}
