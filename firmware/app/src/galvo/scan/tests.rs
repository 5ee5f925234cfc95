extern crate std;

use std::vec::Vec;

use galvo_planner::{JumpSync, Method, XyStepper, plan_xy_jump};
use kinematics_core::{Galvo, MirrorAngles, PointMm};

use super::*;

/// Runs the loop in 128-sample halves until `until` says stop (at most
/// 1 s of samples); returns every sample and every event with the index
/// of the sample after which it happened.
fn run(
    galvo: &mut GalvoLoop,
    mut until: impl FnMut(&[(usize, GalvoEvent)]) -> bool,
) -> (Vec<DacSample>, Vec<(usize, GalvoEvent)>) {
    let mut samples = Vec::new();
    let mut events = Vec::new();
    let mut half = [DacSample::default(); 128];
    while !until(&events) && samples.len() < 100_000 {
        let base = samples.len();
        let mut local = Vec::new();
        galvo.fill(&mut half, |e| local.push(e));
        events.extend(local.into_iter().map(|e| (base, e)));
        samples.extend_from_slice(&half);
    }
    (samples, events)
}

fn point(seq: u32, x_mm: f32, y_mm: f32, dwell_us: u32) -> GalvoRequest {
    GalvoRequest::Point {
        seq,
        x_mm,
        y_mm,
        dwell_us,
    }
}

fn spot_mm(s: &DacSample) -> PointMm {
    Galvo::<f64>::default()
        .codes_to_board(s.x_code, s.y_code)
        .unwrap()
}

fn done(seq: u32) -> impl FnMut(&[(usize, GalvoEvent)]) -> bool {
    move |events| events.iter().any(|(_, e)| *e == GalvoEvent::Done { seq })
}

#[test]
fn a_point_is_a_planned_jump_a_delay_a_dwell_and_a_delay() {
    let config = GalvoConfig::default();
    let mut galvo = GalvoLoop::new(config).unwrap();
    assert_eq!(galvo.request(point(1, 60.0, -35.0, 500)), None);
    let (samples, _) = run(&mut galvo, done(1));

    // The jump is exactly the planner's: same input, same f32 stepper.
    let disc = config.mirrors.model().unwrap().discretize(10e-6).unwrap();
    let target = Galvo::<f64>::default()
        .geometry
        .ik(PointMm {
            x_mm: 60.0,
            y_mm: -35.0,
        })
        .unwrap();
    let jump = plan_xy_jump(
        &disc,
        &disc,
        [0.0, 0.0],
        [target.x_rad, target.y_rad],
        Method::TimeOptimal,
        JumpSync::Independent,
        STEPPER_CAPACITY,
    )
    .unwrap();
    let mut reference: XyStepper<3, STEPPER_CAPACITY> =
        XyStepper::new(&disc, &disc, [0.0, 0.0]).unwrap();
    reference.queue_jump(&jump).unwrap();
    let n_jump = jump.samples();
    assert!(n_jump > 10, "a 70 mm jump takes {n_jump} samples");
    for (k, s) in samples.iter().take(n_jump).enumerate() {
        let [x_rad, y_rad] = reference.step();
        let codes = config
            .galvo
            .angles_to_codes(MirrorAngles { x_rad, y_rad })
            .unwrap();
        assert_eq!(
            (s.x_code, s.y_code),
            (codes.x.code, codes.y.code),
            "sample {k}"
        );
        assert!(!s.laser, "laser off during the jump (sample {k})");
    }
    // Then 10 samples of laser-on delay, 50 of dwell, 10 of laser-off delay.
    let after: Vec<bool> = samples[n_jump..n_jump + 70]
        .iter()
        .map(|s| s.laser)
        .collect();
    assert!(after[..10].iter().all(|on| !on));
    assert!(after[10..60].iter().all(|on| *on));
    assert!(after[60..].iter().all(|on| !on));
    assert_eq!(samples.iter().filter(|s| s.laser).count(), 50);
    // At rest on the point: within 0.1 mm (one DAC LSB is ~0.085 mm).
    for s in samples[n_jump..n_jump + 70].iter() {
        let p = spot_mm(s);
        assert!(
            (p.x_mm - 60.0).abs() < 0.1 && (p.y_mm + 35.0).abs() < 0.1,
            "{p:?}"
        );
    }
    assert_eq!(galvo.phase(), Phase::Idle);
}

#[test]
fn points_run_in_order_and_the_seed_planner_lands_them_too() {
    let mut galvo = GalvoLoop::new(GalvoConfig {
        method: Method::SEED,
        ..GalvoConfig::default()
    })
    .unwrap();
    let targets = [(1, -80.0, 50.0), (2, 80.0, 50.0), (3, 0.0, -60.0)];
    for (seq, x, y) in targets {
        assert_eq!(galvo.request(point(seq, x, y, 200)), None);
    }
    let (samples, events) = run(&mut galvo, done(3));
    let order: Vec<GalvoEvent> = events.iter().map(|(_, e)| *e).collect();
    assert_eq!(
        order,
        [1, 2, 3].map(|seq| GalvoEvent::Done { seq }).to_vec()
    );
    // Every lit sample is on one of the targets.
    for s in samples.iter().filter(|s| s.laser) {
        let p = spot_mm(s);
        assert!(
            targets
                .iter()
                .any(|&(_, x, y)| (p.x_mm - f64::from(x)).abs() < 0.1
                    && (p.y_mm - f64::from(y)).abs() < 0.1),
            "lit at {p:?}"
        );
    }
    assert_eq!(samples.iter().filter(|s| s.laser).count(), 3 * 20);
}

#[test]
fn bad_points_are_refused_and_change_nothing() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    assert_eq!(
        galvo.request(point(7, 1000.0, 0.0, 100)),
        Some(GalvoEvent::Refused {
            seq: 7,
            error: GalvoError::OutOfRange
        })
    );
    assert_eq!(
        galvo.request(point(8, f32::NAN, 0.0, 100)),
        Some(GalvoEvent::Refused {
            seq: 8,
            error: GalvoError::Kinematics
        })
    );
    assert_eq!(galvo.phase(), Phase::Idle);
    let (samples, events) = run(&mut galvo, |_| false);
    assert!(events.is_empty());
    assert!(
        samples.iter().all(|s| *s == samples[0] && !s.laser),
        "holds the centre, laser off"
    );
    for seq in 0..4 {
        assert_eq!(galvo.request(point(seq, 1.0, 1.0, 0)), None);
    }
    assert!(matches!(
        galvo.request(point(9, 1.0, 1.0, 0)),
        Some(GalvoEvent::Refused {
            error: GalvoError::QueueFull,
            ..
        })
    ));
}

#[test]
fn stop_turns_the_laser_off_at_the_next_sample() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    galvo.request(point(1, 10.0, 10.0, 100_000));
    galvo.request(point(2, -10.0, 10.0, 100_000));
    let mut half = [DacSample::default(); 128];
    while !half.iter().any(|s| s.laser) {
        galvo.fill(&mut half, |_| {});
    }
    assert_eq!(galvo.phase(), Phase::Dwelling);
    let held = half[127];
    galvo.stop();
    let mut events = Vec::new();
    galvo.fill(&mut half, |e| events.push(e));
    assert!(
        half.iter()
            .all(|s| !s.laser && s.x_code == held.x_code && s.y_code == held.y_code)
    );
    assert!(
        events.is_empty(),
        "the stopped points are not reported done"
    );
    assert_eq!(galvo.phase(), Phase::Idle);
    assert_eq!(galvo.queued_points(), 0);
}

#[test]
fn stop_during_a_jump_lands_and_holds_dark() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    galvo.request(point(1, 90.0, 90.0, 1000));
    let mut half = [DacSample::default(); 8];
    galvo.fill(&mut half, |_| {});
    assert_eq!(galvo.phase(), Phase::Jumping);
    galvo.stop();
    let (samples, events) = run(&mut galvo, |_| false);
    assert!(events.is_empty());
    assert!(samples.iter().all(|s| !s.laser));
    let last = spot_mm(samples.last().unwrap());
    assert!(
        (last.x_mm - 90.0).abs() < 0.1 && (last.y_mm - 90.0).abs() < 0.1,
        "{last:?}"
    );
    assert_eq!(galvo.phase(), Phase::Idle);
}

#[test]
fn delays_round_up_to_whole_samples() {
    assert_eq!(samples_for(100, 10e-6), 10);
    assert_eq!(samples_for(101, 10e-6), 11);
    assert_eq!(samples_for(0, 10e-6), 0);
}

#[test]
fn an_underrun_latches_the_laser_off_until_stop() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    galvo.request(point(1, 5.0, 5.0, 100_000));
    let mut half = [DacSample::default(); 128];
    while !half.iter().any(|s| s.laser) {
        galvo.fill(&mut half, |_| {});
    }
    galvo.underrun();
    galvo.fill(&mut half, |_| {});
    assert!(half.iter().all(|s| !s.laser));
    assert_eq!(
        galvo.request(point(2, 0.0, 0.0, 100)),
        Some(GalvoEvent::Refused {
            seq: 2,
            error: GalvoError::Faulted
        })
    );
    assert_eq!(galvo.request(GalvoRequest::Stop), None);
    assert_eq!(galvo.request(point(3, 0.0, 0.0, 100)), None);
}
