//! The per-sample integrator during a jump, the path sampler on lines and
//! arcs, and adding a segment to the look-ahead planner.

use core::hint::black_box;

use galvo_planner::{JumpSync, MarkLimits, Method, PathPlanner, XyIntegrator, plan_xy_jump};

use crate::harness::{Bench, CAPACITY, deg, reference_plant_at_10us, window};

/// The path planner's limits in these benchmarks.
const LIMITS: MarkLimits = MarkLimits {
    speed_mm_s: 1000.0,
    accel_mm_s2: 1.0e5,
    junction_deviation_mm: 0.01,
    ts_s: 10e-6,
};

/// The per-sample integrator during a jump, the path sampler on lines and
/// arcs, and adding a segment to the look-ahead planner.
pub fn integrator_and_path(b: &mut Bench) {
    integrator_step(b);
    path_sampling(b);
    path_adding(b);
}

/// The two-axis integrator's step while both axes run queued jumps.
#[inline(always)]
fn integrator_step(b: &mut Bench) {
    let disc = match reference_plant_at_10us() {
        Ok(d) => d,
        Err(e) => return b.fail("integrator.setup", e),
    };
    let mut mirrors: XyIntegrator<3, CAPACITY> = match XyIntegrator::new(&disc, &disc, [0.0, 0.0]) {
        Ok(m) => m,
        Err(e) => return b.fail("integrator.setup", e),
    };
    // Four queued jumps back and forth, both axes moving; the window
    // covers the samples while both run.
    let (a, z) = ([0.0, 0.0], [deg(10.0), deg(-8.0)]);
    for (from, to) in [(a, z), (z, a), (a, z), (z, a)] {
        let queued = plan_xy_jump(
            &disc,
            &disc,
            from,
            to,
            Method::TimeOptimal,
            JumpSync::Independent,
            CAPACITY,
        )
        .and_then(|jump| mirrors.queue_jump(&jump));
        if let Err(e) = queued {
            return b.fail("integrator.setup", e);
        }
    }
    let steps = mirrors
        .x
        .remaining_samples()
        .min(mirrors.y.remaining_samples()) as u32;
    b.repeat("integrator.xy.step", steps, || mirrors.step());
}

/// The path sampler in the cruise phase of a line and of an arc.
#[inline(always)]
fn path_sampling(b: &mut Bench) {
    let line = PathPlanner::<16>::new(LIMITS, [-80.0, 10.0]).and_then(|mut p| {
        p.line_to([80.0, -10.0])?;
        Ok(p)
    });
    let arc = PathPlanner::<16>::new(LIMITS, [0.0, 40.0]).and_then(|mut p| {
        p.arc_to([0.0, 40.0], [0.0, 0.0], true)?;
        Ok(p)
    });
    for (id, planner) in [("path.sample.line", line), ("path.sample.arc", arc)] {
        let mut planner = match planner {
            Ok(p) => p,
            Err(e) => return b.fail(id, e),
        };
        // Into the cruise phase, then a window of samples.
        for _ in 0..2000 {
            planner.next_sample();
        }
        b.repeat(id, 1000, || planner.next_sample());
    }
}

/// Adding one segment (line or arc) to the look-ahead planner.
#[inline(always)]
fn path_adding(b: &mut Bench) {
    // One segment added behind eight buffered ones (junction speed and the
    // backward/forward passes over the buffer).
    let polyline: [[f64; 2]; 8] = core::array::from_fn(|i| {
        let x = -80.0 + 20.0 * i as f64;
        [x, if i % 2 == 0 { 10.0 } else { -10.0 }]
    });
    for (id, arc) in [("path.add.line", false), ("path.add.arc", true)] {
        let (mut ticks, mut units) = (0u32, 0u32);
        for _ in 0..32 {
            let mut p = match PathPlanner::<16>::new(LIMITS, [-100.0, 0.0]) {
                Ok(p) => p,
                Err(e) => return b.fail(id, e),
            };
            if let Err(e) = p.extend_polyline(&polyline, false) {
                return b.fail(id, e);
            }
            let p = &mut p;
            // The pen is at (60, −10) mm.
            let mut added = Ok(());
            ticks += window(|| {
                added = if arc {
                    p.arc_to(black_box([90.0, -10.0]), black_box([75.0, -10.0]), true)
                } else {
                    p.line_to(black_box([90.0, 0.0]))
                };
            });
            if let Err(e) = added {
                return b.fail(id, e);
            }
            units += 1;
        }
        b.report(id, ticks, units);
    }
}
