//! Planning time per jump for each method, per-sample integrator cost (f32),
//! path-planner cost per added segment and per sample.
//!
//! `cargo bench -p galvo-planner -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use galvo_planner::integrator::Integrator;
use galvo_planner::jump::{Method, plan_jump};
use galvo_planner::model::{Discrete, FlexParams, RigidParams};
use galvo_planner::path::{MarkLimits, PathPlanner};

const DEG: f64 = std::f64::consts::PI / 180.0;

fn rigid(ts: f64) -> Discrete<3> {
    RigidParams::REFERENCE
        .model()
        .and_then(|m| m.discretize(ts))
        .expect("reference")
}

fn flex(ts: f64) -> Discrete<5> {
    FlexParams::REFERENCE
        .model()
        .and_then(|m| m.discretize(ts))
        .expect("reference")
}

fn planning(c: &mut Criterion) {
    let mut g = c.benchmark_group("plan_jump");
    for (ts, ts_name) in [(10e-6, "10us"), (1e-6, "1us")] {
        let d = rigid(ts);
        for (method, name) in [
            (Method::TimeOptimal, "optimal"),
            (Method::BISECTION, "seed"),
            (Method::TCurve, "tcurve"),
            (Method::SCurve, "scurve"),
        ] {
            for step in [1.0, 20.0] {
                g.bench_function(format!("{name}/{step}deg/{ts_name}"), |b| {
                    b.iter(|| {
                        plan_jump(&d, 0.0, black_box(step * DEG), method, 100_000).expect("plan")
                    })
                });
            }
        }
    }
    let f = flex(10e-6);
    g.bench_function("seed/20deg/10us/flexible", |b| {
        b.iter(|| {
            plan_jump(&f, 0.0, black_box(20.0 * DEG), Method::BISECTION, 100_000).expect("plan")
        })
    });
    g.finish();
}

fn stepping(c: &mut Criterion) {
    const BLOCK: usize = 64;
    let mut g = c.benchmark_group("integrator");
    g.throughput(Throughput::Elements(BLOCK as u64));
    let d = rigid(10e-6);
    let plan = plan_jump(&d, -10.0 * DEG, 10.0 * DEG, Method::BISECTION, 4096).expect("plan");
    assert!(plan.samples() >= BLOCK);
    let mut st: Integrator<3, 1024> = Integrator::new(&d, -10.0 * DEG).expect("integrator");
    st.queue(&plan).expect("queue");
    g.bench_function("rigid_f32/block64", |b| {
        b.iter_batched_ref(
            || (st.clone(), [0.0f32; BLOCK]),
            |(s, buf)| s.fill(black_box(buf)),
            BatchSize::SmallInput,
        )
    });
    let f = flex(10e-6);
    let plan = plan_jump(&f, -10.0 * DEG, 10.0 * DEG, Method::BISECTION, 4096).expect("plan");
    let mut sf: Integrator<5, 1024> = Integrator::new(&f, -10.0 * DEG).expect("integrator");
    sf.queue(&plan).expect("queue");
    g.bench_function("flexible_f32/block64", |b| {
        b.iter_batched_ref(
            || (sf.clone(), [0.0f32; BLOCK]),
            |(s, buf)| s.fill(black_box(buf)),
            BatchSize::SmallInput,
        )
    });
    let idle: Integrator<3, 1024> = Integrator::new(&d, 0.1).expect("integrator");
    g.bench_function("rigid_idle_hold/block64", |b| {
        b.iter_batched_ref(
            || (idle.clone(), [0.0f32; BLOCK]),
            |(s, buf)| s.fill(black_box(buf)),
            BatchSize::SmallInput,
        )
    });
    g.finish();
}

fn marking(c: &mut Criterion) {
    let limits = MarkLimits {
        speed_mm_s: 1000.0,
        accel_mm_s2: 1.0e5,
        junction_deviation_mm: 0.01,
        ts_s: 10e-6,
    };
    // A zig-zag of 2 mm segments, so every junction is a real corner.
    let point = |i: usize| [2.0 * i as f64, if i.is_multiple_of(2) { 0.0 } else { 1.0 }];
    let mut g = c.benchmark_group("path");
    g.throughput(Throughput::Elements(1));
    for prefill in [1usize, 15, 30] {
        let mut p: PathPlanner<32> = PathPlanner::new(limits, [0.0, 0.0]).expect("planner");
        for i in 1..=prefill {
            p.line_to(point(i)).expect("room");
        }
        // Start executing the first block, as in steady state.
        let _ = p.next_sample();
        let next = point(prefill + 1);
        g.bench_function(format!("add_segment/buffer{prefill}"), |b| {
            b.iter_batched_ref(
                || p.clone(),
                |pl| pl.line_to(black_box(next)).expect("room"),
                BatchSize::SmallInput,
            )
        });
    }
    const BLOCK: usize = 256;
    g.throughput(Throughput::Elements(BLOCK as u64));
    let mut lines: PathPlanner<32> = PathPlanner::new(limits, [0.0, 0.0]).expect("planner");
    lines.line_to([100.0, 50.0]).expect("room");
    for _ in 0..100 {
        let _ = lines.next_sample();
    }
    g.bench_function("sample_line/block256", |b| {
        b.iter_batched_ref(
            || (lines.clone(), [[0.0f32; 2]; BLOCK]),
            |(pl, buf)| pl.fill(black_box(buf)),
            BatchSize::SmallInput,
        )
    });
    let mut arcs: PathPlanner<32> = PathPlanner::new(limits, [20.0, 0.0]).expect("planner");
    arcs.arc_to([20.0, 0.0], [0.0, 0.0], true).expect("room");
    for _ in 0..100 {
        let _ = arcs.next_sample();
    }
    g.bench_function("sample_arc/block256", |b| {
        b.iter_batched_ref(
            || (arcs.clone(), [[0.0f32; 2]; BLOCK]),
            |(pl, buf)| pl.fill(black_box(buf)),
            BatchSize::SmallInput,
        )
    });
    g.finish();
}

criterion_group!(benches, planning, stepping, marking);
criterion_main!(benches);
