//! The measurement pipeline per frame at 1280 × 720 (issue 22: ≥ 30
//! frames/s on one host core, so the same code can close a tracking
//! loop): with the camera fixed the board's homography is found once, so
//! a frame costs the spot detection against the laser-off frame and the
//! mapping onto the board. Marker detection (once per set-up) is timed
//! too, for scale.
//!
//! `cargo bench -p camera-calib --bench pipeline -- --warm-up-time 1 --measurement-time 5`
//! (median time per frame: `target/criterion/pipeline/*/new/estimates.json`).

use std::hint::black_box;

use camera_calib::camera::Camera;
use camera_calib::markers::MarkerDetector;
use camera_calib::measure::locate_board;
use camera_calib::render::{Exposure, LaserSpot, VirtualCamera};
use camera_calib::target::{GridSpec, TargetLayout};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

fn pipeline(c: &mut Criterion) {
    let Ok(layout) = TargetLayout::for_grid(GridSpec::default()) else {
        panic!("default target")
    };
    let vc = VirtualCamera {
        camera: Camera::reference(0.0),
        layout,
        exposure: Exposure::default(),
    };
    let scene = vc.scene();
    let background = vc.averaged_frame(&scene, &[], 8, 1);
    // One exposure per frame, as a tracking loop sees them.
    let frame = vc.frame(&scene, &[LaserSpot::at([57.48, -38.32])], 2);
    let mut detector = match MarkerDetector::new(background.width, background.height) {
        Ok(d) => d,
        Err(e) => panic!("detector: {e}"),
    };
    let view = match locate_board(&mut detector, &background, &vc.layout, None) {
        Ok(v) => v,
        Err(e) => panic!("board: {e}"),
    };
    let mut group = c.benchmark_group("pipeline");
    group.throughput(Throughput::Elements(1));
    group.bench_function("frame 1280x720: spot + board mm (fixed homography)", |b| {
        b.iter(|| view.measure(black_box(&background), black_box(&frame)))
    });
    group.sample_size(10);
    group.bench_function("marker detection + homography (once per set-up)", |b| {
        b.iter(|| locate_board(&mut detector, black_box(&background), &vc.layout, None))
    });
    group.finish();
}

criterion_group!(benches, pipeline);
criterion_main!(benches);
