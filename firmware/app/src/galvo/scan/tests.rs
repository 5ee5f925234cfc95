extern crate std;

use std::vec::Vec;

use galvo_planner::{JumpSync, Method, XyIntegrator, plan_xy_jump};
use kinematics_core::{Galvo, MirrorAngles, PointMm};

use super::build::samples_for;
use super::types::{INTEGRATOR_CAPACITY, MARK_BLOCKS};
use super::*;
use crate::domain::{Figure, PointCm};
use crate::galvo::{GalvoMemory, GalvoRequest};

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

    // The jump is exactly the planner's: same input, same f32 integrator.
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
        INTEGRATOR_CAPACITY,
    )
    .unwrap();
    let mut reference: XyIntegrator<3, INTEGRATOR_CAPACITY> =
        XyIntegrator::new(&disc, &disc, [0.0, 0.0]).unwrap();
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
    assert_eq!(galvo.phase(), ScanPhase::Idle);
}

#[test]
fn points_run_in_order_and_the_seed_planner_lands_them_too() {
    let mut galvo = GalvoLoop::new(GalvoConfig {
        method: Method::BISECTION,
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
    assert_eq!(galvo.phase(), ScanPhase::Idle);
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
    assert_eq!(galvo.phase(), ScanPhase::Dwelling);
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
    assert_eq!(galvo.phase(), ScanPhase::Idle);
    assert_eq!(galvo.queued_points(), 0);
}

#[test]
fn stop_during_a_jump_lands_and_holds_dark() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    galvo.request(point(1, 90.0, 90.0, 1000));
    let mut half = [DacSample::default(); 8];
    galvo.fill(&mut half, |_| {});
    assert_eq!(galvo.phase(), ScanPhase::Jumping);
    galvo.stop();
    let (samples, events) = run(&mut galvo, |_| false);
    assert!(events.is_empty());
    assert!(samples.iter().all(|s| !s.laser));
    let last = spot_mm(samples.last().unwrap());
    assert!(
        (last.x_mm - 90.0).abs() < 0.1 && (last.y_mm - 90.0).abs() < 0.1,
        "{last:?}"
    );
    assert_eq!(galvo.phase(), ScanPhase::Idle);
}

#[test]
fn holding_computes_one_sample_and_outputs_what_a_full_fill_would() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    let centre = galvo.hold_sample().expect("idle at boot");
    assert!(!centre.laser);
    let mut half = [DacSample::default(); 128];
    assert_eq!(galvo.fill(&mut half, |_| {}), 1, "one computed sample");
    assert!(half.iter().all(|s| *s == centre));
    // Busy: no hold, every sample computed.
    galvo.request(point(1, 30.0, -20.0, 300));
    assert_eq!(galvo.hold_sample(), None);
    assert_eq!(galvo.fill(&mut half, |_| {}), 128);
    let (samples, _) = run(&mut galvo, done(1));
    // The last samples of the job (laser-off delay) are the hold that
    // follows, at the point: the fast path changes nothing in the output.
    let last = *samples.last().unwrap();
    let hold = galvo.hold_sample().expect("idle after the point");
    assert_eq!(
        hold,
        DacSample {
            laser: false,
            ..last
        }
    );
    let p = spot_mm(&hold);
    assert!(
        (p.x_mm - 30.0).abs() < 0.1 && (p.y_mm + 20.0).abs() < 0.1,
        "{p:?}"
    );
    // New parameters waiting: not a plain hold until they are applied.
    galvo.configure(GalvoConfig {
        laser_on_delay_us: 300,
        ..GalvoConfig::default()
    });
    assert_eq!(galvo.hold_sample(), None);
    galvo.fill(&mut half, |_| {});
    assert_eq!(galvo.hold_sample(), Some(hold));
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

fn path(seq: u32, path: Figure) -> GalvoRequest {
    GalvoRequest::Path {
        seq,
        path,
        mark_speed_mm_s: None,
    }
}

/// Distance (mm) from `p` to the border of the axis-aligned rectangle.
fn off_rect(p: PointMm, lo: [f64; 2], hi: [f64; 2]) -> f64 {
    let inside_x = p.x_mm.clamp(lo[0], hi[0]);
    let inside_y = p.y_mm.clamp(lo[1], hi[1]);
    let outside = (p.x_mm - inside_x).hypot(p.y_mm - inside_y);
    let inside = (p.x_mm - lo[0])
        .abs()
        .min((p.x_mm - hi[0]).abs())
        .min((p.y_mm - lo[1]).abs())
        .min((p.y_mm - hi[1]).abs());
    if outside > 0.0 { outside } else { inside }
}

/// Largest DAC step between consecutive samples.
fn largest_step(samples: &[DacSample]) -> u16 {
    samples
        .windows(2)
        .map(|w| {
            w[0].x_code
                .abs_diff(w[1].x_code)
                .max(w[0].y_code.abs_diff(w[1].y_code))
        })
        .max()
        .unwrap_or(0)
}

#[test]
fn a_rectangle_is_marked_on_its_border_at_the_marking_speed() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    // (-40, 30) mm to (40, -30) mm.
    let rect = Figure::Rect {
        a: PointCm::new(-4.0, 3.0),
        b: PointCm::new(4.0, -3.0),
    };
    assert_eq!(galvo.request(path(1, rect)), None);
    let (samples, events) = run(&mut galvo, done(1));
    assert_eq!(events.len(), 1);
    let lit: Vec<&DacSample> = samples.iter().filter(|s| s.laser).collect();
    // 280 mm of border at ≤ 1 m/s: at least 28 ms of marking.
    assert!(lit.len() >= 2800, "{} lit samples", lit.len());
    for s in &lit {
        let p = spot_mm(s);
        // DAC quantisation: one LSB is ~0.085 mm here.
        assert!(off_rect(p, [-40.0, -30.0], [40.0, 30.0]) < 0.15, "{p:?}");
    }
    // Marking never outruns 1000 mm/s (10 µs samples: 0.01 mm + 1 LSB).
    let mut prev: Option<PointMm> = None;
    for s in samples.iter() {
        let p = spot_mm(s);
        if let (Some(q), true) = (prev, s.laser) {
            assert!((p.x_mm - q.x_mm).hypot(p.y_mm - q.y_mm) < 0.01 + 0.13);
        }
        prev = Some(p);
    }
    // One unbroken lit run that starts and ends at corner a.
    let first = samples.iter().position(|s| s.laser).unwrap();
    let last = samples.iter().rposition(|s| s.laser).unwrap();
    assert!(samples[first..=last].iter().all(|s| s.laser));
    for k in [first, last] {
        let p = spot_mm(&samples[k]);
        assert!(
            (p.x_mm + 40.0).abs() < 0.15 && (p.y_mm - 30.0).abs() < 0.15,
            "{p:?}"
        );
    }
}

#[test]
fn the_tuning_figure_is_four_strokes_with_jumps_between() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    // Centre (10, -5) mm, half size 25 mm.
    let figure = Figure::Tuning {
        centre: PointCm::new(1.0, -0.5),
        size_cm: 5.0,
    };
    galvo.request(path(1, figure));
    let (samples, _) = run(&mut galvo, done(1));
    let switches_on = samples
        .windows(2)
        .filter(|w| !w[0].laser && w[1].laser)
        .count();
    assert_eq!(switches_on, 4, "square, circle, horizontal, vertical");
    for s in samples.iter().filter(|s| s.laser) {
        let p = spot_mm(s);
        let (dx, dy) = (p.x_mm - 10.0, p.y_mm + 5.0);
        let on_square = off_rect(p, [-15.0, -30.0], [35.0, 20.0]) < 0.15;
        let on_circle = (dx.hypot(dy) - 25.0).abs() < 0.15;
        let on_cross =
            (dy.abs() < 0.15 && dx.abs() <= 25.15) || (dx.abs() < 0.15 && dy.abs() <= 25.15);
        assert!(
            on_square || on_circle || on_cross,
            "lit off the figure at {p:?}"
        );
    }
}

#[test]
fn stop_while_marking_brakes_dark_without_a_jump() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    galvo.request(path(
        1,
        // (-60, 0) mm to (60, 0) mm.
        Figure::Line {
            from: PointCm::new(-6.0, 0.0),
            to: PointCm::new(6.0, 0.0),
        },
    ));
    let mut half = [DacSample::default(); 128];
    let mut samples = Vec::new();
    // Mark until the spot is at full speed, well into the line.
    while samples.iter().filter(|s: &&DacSample| s.laser).count() < 3000 {
        galvo.fill(&mut half, |_| {});
        samples.extend_from_slice(&half);
    }
    assert_eq!(galvo.phase(), ScanPhase::Marking);
    let marking_step = largest_step(&samples[samples.len() - 128..]);
    galvo.stop();
    let (after, events) = run(&mut galvo, |_| false);
    assert!(events.is_empty());
    assert!(after.iter().all(|s| !s.laser), "dark from the next sample");
    assert_eq!(galvo.phase(), ScanPhase::Idle);
    let mut joined = samples[samples.len() - 1..].to_vec();
    joined.extend_from_slice(&after);
    assert!(
        largest_step(&joined) <= marking_step,
        "no jump when stopping"
    );
    // It kept moving forward while braking (1 m/s at 1e5 mm/s²: 5 mm).
    let (before, end) = (spot_mm(&joined[0]), spot_mm(after.last().unwrap()));
    assert!(
        end.x_mm - before.x_mm > 3.0 && end.x_mm - before.x_mm < 7.0,
        "{before:?} → {end:?}"
    );
    // And it can jump again from there.
    galvo.request(point(2, 0.0, 0.0, 100));
    let (_, events) = run(&mut galvo, done(2));
    assert_eq!(events.len(), 1);
}

/// The refill works run by run (a phase's samples in a loop of its own):
/// how the samples are cut into halves changes nothing, across jumps,
/// dwells, strokes, stroke ends and a stop while marking.
#[test]
fn halves_of_any_length_give_the_same_samples() {
    let stream = |half_len: usize| {
        let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
        let jobs = [
            point(1, 60.0, -35.0, 500),
            path(
                2,
                Figure::Tuning {
                    centre: PointCm::new(0.5, -0.3),
                    size_cm: 6.0,
                },
            ),
            point(3, -10.0, 5.0, 0),
            path(
                4,
                Figure::Rect {
                    a: PointCm::new(-3.0, -3.0),
                    b: PointCm::new(3.0, 2.0),
                },
            ),
        ];
        for job in jobs {
            assert_eq!(galvo.request(job), None);
        }
        let mut samples = Vec::new();
        let mut half = [DacSample::default(); 128];
        while samples.len() < 60_000 {
            // A stop at the same sample for every half length.
            if samples.len() == 51_200 {
                galvo.request(GalvoRequest::Stop);
            }
            galvo.fill(&mut half[..half_len], |_| {});
            samples.extend_from_slice(&half[..half_len]);
        }
        samples.truncate(60_000);
        samples
    };
    let whole = stream(128);
    assert!(whole.iter().filter(|s| s.laser).count() > 10_000);
    for half_len in [1, 32, 100] {
        assert!(stream(half_len) == whole, "half of {half_len}");
    }
}

#[test]
fn the_path_planner_holds_the_longest_stroke() {
    // One block per segment: the loop loads a whole stroke before marking.
    let capacity = crate::domain::Segments::new().capacity();
    assert!(
        MARK_BLOCKS >= capacity,
        "{MARK_BLOCKS} blocks < {capacity} segments"
    );
}

/// The loop's own memory on the host (64-bit: at least the target's),
/// held in the board's `static` (`GalvoMemory`). Budget: the galvo task
/// must stay well under 30 KB of the target's 96 KB static RAM.
const GALVO_LOOP_MAX_BYTES: usize = 24 * 1024;

#[test]
fn the_galvo_loop_stays_within_its_memory_budget() {
    let size = core::mem::size_of::<GalvoLoop>();
    std::println!("GalvoLoop: {size} B on the host");
    assert!(size <= GALVO_LOOP_MAX_BYTES, "GalvoLoop is {size} B");
}

/// A board whose CPU has a single-precision FPU only (the default
/// [`DacStream::F64_PLANNING`]), like the STM32's.
struct M4Dac;

impl DacStream for M4Dac {
    fn half_len(&self) -> usize {
        128
    }
    fn set_sample_period(&mut self, _period_s: f64) {}
    fn holds(&self, _sample: DacSample) -> bool {
        false
    }
    async fn write_half(&mut self, _half: Half<'_>) -> Result<(), crate::galvo::Underrun> {
        Ok(())
    }
    async fn repeat_half(&mut self) {}
}

#[test]
fn a_board_that_cannot_afford_bisection_refuses_seed_parameters() {
    let seed = GalvoConfig {
        method: Method::BISECTION,
        ..GalvoConfig::default()
    };
    // The M4: refused, at build and as new parameters (nothing changes).
    assert_eq!(
        GalvoLoop::for_dac::<M4Dac>(seed).err(),
        Some(GalvoError::SeedTooSlow)
    );
    let mut m4 = GalvoLoop::for_dac::<M4Dac>(GalvoConfig::default()).unwrap();
    m4.configure(seed);
    assert_eq!(
        m4.apply_pending_config(true),
        Some(GalvoEvent::ConfigRefused(GalvoError::SeedTooSlow))
    );
    assert_eq!(m4.config.method, Method::TimeOptimal);
    // Its f32-only jump plans are the host's time-optimal ones.
    let mut host = GalvoLoop::new(GalvoConfig::default()).unwrap();
    let point = GalvoRequest::Point {
        seq: 1,
        x_mm: 80.0,
        y_mm: -80.0,
        dwell_us: 0,
    };
    for galvo in [&mut m4, &mut host] {
        galvo.request(point);
        assert_eq!(galvo.prep(), 1);
    }
    let jump = |g: &GalvoLoop| g.steps.get(0).map(|s| s.jump);
    assert!(matches!(jump(&m4), Some(Ok(_))));
    assert_eq!(jump(&m4), jump(&host));
    // A host loop plans by bisection, and counts it for the cost model.
    let mut host = GalvoLoop::new(GalvoConfig::default()).unwrap();
    host.configure(seed);
    assert_eq!(host.apply_pending_config(true), None);
    host.request(point);
    host.work = crate::galvo::LoopWork::default();
    host.prep();
    assert_eq!(host.work.bisection_axes, 2);
}

#[test]
fn memory_init_in_place_is_an_empty_dark_memory() {
    let mut slot = core::mem::MaybeUninit::<GalvoMemory<64>>::uninit();
    let memory = GalvoMemory::init_in(&mut slot);
    assert!(memory.galvo.is_none());
    assert!(
        memory
            .half
            .iter()
            .all(|s| *s == DacSample::default() && !s.laser)
    );
    // The loop started in place equals one built by value.
    let galvo = GalvoLoop::start_in::<M4Dac>(&mut memory.galvo, GalvoConfig::default())
        .expect("default loop");
    let built = GalvoLoop::for_dac::<M4Dac>(GalvoConfig::default()).expect("default loop");
    assert_eq!(galvo.phase(), built.phase());
    assert_eq!(
        galvo.mirrors.end_position_rad(),
        built.mirrors.end_position_rad()
    );
    assert_eq!(galvo.mirrors.x.end_state(), built.mirrors.x.end_state());
    assert_eq!(galvo.last, built.last);
}
