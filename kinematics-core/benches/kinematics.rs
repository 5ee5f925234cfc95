//! Criterion benchmarks of the per-point and per-sample hot paths.
//!
//! `cargo bench -p kinematics-core -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use kinematics_core::{
    BoardPoint, ErrorModel, Galvo, Gimbal, GimbalModel, Grid, JointAngles, Pattern, PointMm,
    gimbal::exact,
};

fn gimbal(c: &mut Criterion) {
    let g = Gimbal::default();
    let target = BoardPoint::new(-9.58, 5.748);
    let joints = g.ik(target).unwrap_or_default();
    let mut group = c.benchmark_group("gimbal");
    group.bench_function("exact ik (raw, global point)", |b| {
        let p = g.geometry.frame.board_to_global(target).unwrap_or_default();
        b.iter(|| exact::ik(black_box(5.4), black_box(p)))
    });
    group.bench_function("exact ik (Gimbal: frame + ik + limits)", |b| {
        b.iter(|| g.ik(black_box(target)))
    });
    group.bench_function("exact ik_wire (… + 0.1° quantisation)", |b| {
        b.iter(|| g.ik_wire(black_box(target)))
    });
    group.bench_function("exact fk (Gimbal)", |b| b.iter(|| g.fk(black_box(joints))));
    let seed = Gimbal::with_model(GimbalModel::Seed);
    group.bench_function("seed ik (Gimbal)", |b| {
        b.iter(|| seed.ik(black_box(target)))
    });
    group.bench_function("seed fk (Gimbal)", |b| {
        b.iter(|| seed.fk(black_box(JointAngles::default())))
    });
    group.finish();
}

fn patterns(c: &mut Criterion) {
    let grid = Grid::default();
    let mut group = c.benchmark_group("pattern");
    group.bench_function("full serpentine, 117 board points", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            if let Ok(points) = Pattern::FullSerpentine.points(black_box(&grid)) {
                for p in points {
                    sum += p.x_cm + p.y_cm;
                }
            }
            sum
        })
    });
    group.finish();
}

fn error_model(c: &mut Criterion) {
    let m = ErrorModel::new(
        [0.8, -2e-3, 1.5e-3, 4e-6, -3e-6, 2e-6],
        [-0.4, 1e-3, 3e-3, -2e-6, 5e-6, 1e-6],
    );
    let target = PointMm::new(95.8, -57.48);
    let mut group = c.benchmark_group("error model");
    group.bench_function("predict", |b| b.iter(|| m.predict(black_box(target))));
    group.bench_function("compensate (fixed point, 1e-10 rel)", |b| {
        b.iter(|| m.compensate(black_box(target)))
    });
    group.finish();
}

fn galvo(c: &mut Criterion) {
    let g32 = Galvo::<f32>::default();
    let g64 = Galvo::<f64>::default();
    let mut group = c.benchmark_group("galvo");
    group.bench_function("f32 ik + DAC codes", |b| {
        b.iter(|| g32.board_to_codes(black_box(PointMm::new(123.4f32, -87.6))))
    });
    group.bench_function("f64 ik + DAC codes", |b| {
        b.iter(|| g64.board_to_codes(black_box(PointMm::new(123.4f64, -87.6))))
    });
    group.bench_function("f32 DAC codes → board (fk)", |b| {
        b.iter(|| g32.codes_to_board(black_box(3100), black_box(1200)))
    });
    group.finish();
}

criterion_group!(benches, gimbal, patterns, error_model, galvo);
criterion_main!(benches);
