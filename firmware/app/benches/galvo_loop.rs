//! Cost of the galvo loop body per DAC sample (host proxy for the
//! target's 10 µs budget at 100 kHz): a half buffer while holding, and a
//! half buffer that plans and runs a full jump.
//!
//! `cargo bench -p laser-app --bench galvo_loop -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use laser_app::domain::{Figure, PointCm};
use laser_app::galvo::{DacSample, GalvoConfig, GalvoLoop, GalvoRequest, ScanPhase};

const HALF: usize = 128;

fn galvo_loop(c: &mut Criterion) {
    let mut group = c.benchmark_group("galvo loop, 128-sample half");
    group.throughput(Throughput::Elements(HALF as u64));
    group.bench_function("holding", |b| {
        let mut galvo = GalvoLoop::new(GalvoConfig::default()).expect("default config");
        let mut half = [DacSample::default(); HALF];
        b.iter(|| galvo.fill(black_box(&mut half), |_| {}));
    });
    for (name, config) in [
        (
            "jump 160 mm, time-optimal plan + samples",
            GalvoConfig::default(),
        ),
        (
            "jump 160 mm, seed plan + samples",
            GalvoConfig {
                method: galvo_planner::Method::BISECTION,
                ..GalvoConfig::default()
            },
        ),
    ] {
        group.bench_function(name, |b| {
            b.iter_batched(
                || {
                    let mut galvo = GalvoLoop::new(config).expect("default config");
                    galvo.request(GalvoRequest::Point {
                        seq: 1,
                        x_mm: 80.0,
                        y_mm: -80.0,
                        dwell_us: 0,
                    });
                    (galvo, [DacSample::default(); HALF])
                },
                |(mut galvo, mut half)| {
                    galvo.fill(black_box(&mut half), |_| {});
                    half
                },
                BatchSize::SmallInput,
            );
        });
    }
    group.bench_function("marking a line (path planner + galvo IK + DAC)", |b| {
        b.iter_batched(
            || {
                let mut galvo = GalvoLoop::new(GalvoConfig::default()).expect("default config");
                galvo.request(GalvoRequest::Path {
                    seq: 1,
                    mark_speed_mm_s: None,
                    // (-80, 10) mm to (80, -10) mm.
                    path: Figure::Line {
                        from: PointCm::new(-8.0, 1.0),
                        to: PointCm::new(8.0, -1.0),
                    },
                });
                let mut half = [DacSample::default(); HALF];
                while galvo.phase() != ScanPhase::Marking {
                    galvo.fill(&mut half, |_| {});
                }
                (galvo, half)
            },
            |(mut galvo, mut half)| {
                galvo.fill(black_box(&mut half), |_| {});
                half
            },
            BatchSize::SmallInput,
        );
    });
    group.finish();
}

criterion_group!(benches, galvo_loop);
criterion_main!(benches);
