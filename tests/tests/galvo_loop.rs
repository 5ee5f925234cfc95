//! The galvo loop body (`laser-app`) feeding the simulated DAC in virtual
//! time: the sample stream is continuous, points are reached within
//! 0.1 mm with the laser on only there, and a loop slower than the sample
//! rate underruns, turns the laser off and says so.

use std::cell::RefCell;
use std::rc::Rc;
use std::sync::atomic::Ordering;

use kinematics_core::Galvo;
use laser_app::galvo::{DacSample, GalvoConfig, GalvoEvent, GalvoLink, GalvoLoop, GalvoRequest};
use laser_app::laser_gate::LaserGate;
use laser_sim::dac::{DacRecording, SimDac};
use laser_sim::executor::{self, RunEnd};

/// Corner points of a 160 mm square and its centre, mm.
const POINTS: [(f32, f32); 5] = [
    (-80.0, 80.0),
    (80.0, 80.0),
    (80.0, -80.0),
    (-80.0, -80.0),
    (0.0, 0.0),
];

struct Run {
    recording: DacRecording,
    events: Vec<GalvoEvent>,
    underruns: u32,
    end: RunEnd,
}

/// Runs the galvo loop (default configuration) on `dac` with `link` and
/// `gate` beside the `driver` task, until the driver returns or
/// `limit_us` of simulated time have passed.
fn run_loop(
    dac: SimDac,
    link: &'static GalvoLink,
    gate: &'static LaserGate,
    limit_us: u64,
    driver: impl Future<Output = ()> + 'static,
) -> RunEnd {
    run_loop_with(GalvoConfig::default(), dac, link, gate, limit_us, driver)
}

/// [`run_loop`] with the loop's `config`.
fn run_loop_with(
    config: GalvoConfig,
    dac: SimDac,
    link: &'static GalvoLink,
    gate: &'static LaserGate,
    limit_us: u64,
    driver: impl Future<Output = ()> + 'static,
) -> RunEnd {
    let finished = Rc::new(RefCell::new(false));
    let fin = finished.clone();
    executor::run(
        false,
        limit_us,
        move |spawner| {
            executor::spawn(&spawner, async move {
                let mut dac = dac;
                let mut galvo = GalvoLoop::new(config).expect("galvo config");
                galvo.run(&mut dac, link, gate).await;
            });
            executor::spawn(&spawner, async move {
                driver.await;
                *fin.borrow_mut() = true;
            });
        },
        move || *finished.borrow(),
    )
}

fn run(compute_ns_per_sample: u64) -> Run {
    let link: &'static GalvoLink = Box::leak(Box::new(GalvoLink::new()));
    let recording = Rc::new(RefCell::new(DacRecording::default()));
    let events: Rc<RefCell<Vec<GalvoEvent>>> = Rc::default();
    let gate = laser_sim::laser::recorded_gate(&recording);
    let dac = SimDac::new(128, 10_000, compute_ns_per_sample, recording.clone());
    let ev = events.clone();
    let end = run_loop(dac, link, gate, 2_000_000, async move {
        for (i, &(x_mm, y_mm)) in POINTS.iter().enumerate() {
            link.requests
                .send(GalvoRequest::Point {
                    seq: i as u32,
                    x_mm,
                    y_mm,
                    dwell_us: 2_000,
                })
                .await;
        }
        // Until every point is done or refused, or an underrun.
        let mut closed = 0;
        while closed < POINTS.len() {
            let event = link.events.receive().await;
            ev.borrow_mut().push(event);
            match event {
                GalvoEvent::Underrun(_) => break,
                _ => closed += 1,
            }
        }
        embassy_time::Timer::after_millis(5).await;
    });
    let recording = recording.borrow().clone();
    let events = events.borrow().clone();
    Run {
        recording,
        events,
        underruns: link.underruns.load(Ordering::Relaxed),
        end,
    }
}

#[test]
fn points_are_reached_with_a_continuous_stream_and_no_underrun() {
    let run = run(0);
    assert_eq!(run.end, RunEnd::Stopped);
    assert_eq!(run.underruns, 0);
    assert!(run.recording.underruns.is_empty());
    assert_eq!(
        run.events,
        (0..5)
            .map(|seq| GalvoEvent::Done { seq })
            .collect::<Vec<_>>()
    );
    let galvo = Galvo::<f64>::default();
    let samples: Vec<DacSample> = run.recording.iter().map(|(_, s)| s).collect();
    // One sample every 10 µs, no gaps.
    let times: Vec<u64> = run.recording.iter().map(|(t, _)| t).collect();
    assert!(times.windows(2).all(|w| w[1] - w[0] == 10_000));
    // Continuous: one sample per period from start to end, whole halves.
    assert_eq!(samples.len() % 128, 0);
    assert!(samples.len() > 5 * 200, "{} samples", samples.len());
    // Laser on exactly at the points: 5 × 2 ms of dwell at 100 kHz.
    let lit: Vec<_> = samples.iter().filter(|s| s.laser).collect();
    assert_eq!(lit.len(), 5 * 200);
    for s in lit {
        let p = galvo
            .codes_to_board(s.x_code, s.y_code)
            .expect("codes in range");
        assert!(
            POINTS
                .iter()
                .any(|&(x, y)| (p.x_mm - f64::from(x)).abs() < 0.1
                    && (p.y_mm - f64::from(y)).abs() < 0.1),
            "lit at ({:.3}, {:.3}) mm",
            p.x_mm,
            p.y_mm
        );
    }
    // Each point's dwell is one unbroken run of lit samples.
    let switches = samples
        .windows(2)
        .filter(|w| w[0].laser != w[1].laser)
        .count();
    assert_eq!(switches, 2 * 5);
}

#[test]
fn a_loop_slower_than_the_sample_rate_underruns_and_turns_the_laser_off() {
    // 12 µs of compute per 10 µs sample.
    let run = run(12_000);
    assert!(run.underruns > 0);
    assert!(
        matches!(run.events.last(), Some(GalvoEvent::Underrun(_))),
        "{:?}",
        run.events
    );
    let (first_replay, halves) = run.recording.underruns[0];
    // After the replayed stale halves (and the two buffers' old content),
    // everything the DAC outputs is dark.
    let after_report = first_replay + (halves as usize + 2) * 128;
    assert!(
        run.recording
            .iter()
            .skip(after_report)
            .all(|(_, s)| !s.laser),
        "laser off after the underrun"
    );
}

#[test]
fn an_underrun_mid_dwell_replays_dark_and_the_laser_is_dark_at_once() {
    // The loop keeps up until it is lit at a point, then becomes slower
    // than the sample rate (15 µs per 10 µs sample) and stays so.
    let link: &'static GalvoLink = Box::leak(Box::new(GalvoLink::new()));
    let recording = Rc::new(RefCell::new(DacRecording::default()));
    let gate = laser_sim::laser::recorded_gate(&recording);
    let dac = SimDac::new(128, 10_000, 0, recording.clone());
    let cost = dac.compute_cost();
    let slowed_at = Rc::new(RefCell::new(None));
    let slowed = slowed_at.clone();
    let end = run_loop(dac, link, gate, 2_000_000, async move {
        link.requests
            .send(GalvoRequest::Point {
                seq: 1,
                x_mm: 20.0,
                y_mm: 10.0,
                dwell_us: 30_000,
            })
            .await;
        embassy_time::Timer::after_millis(10).await;
        cost.set(15_000);
        *slowed.borrow_mut() = Some(embassy_time::Instant::now().as_micros() * 1000);
        loop {
            if let GalvoEvent::Underrun(_) = link.events.receive().await {
                break;
            }
        }
        // Still too slow, but idle: it must hold quietly.
        embassy_time::Timer::after_millis(200).await;
    });
    assert_eq!(end, RunEnd::Stopped);
    let recording = recording.borrow().clone();
    let slowed_ns = slowed_at.borrow().expect("slowed down");
    let samples: Vec<(u64, DacSample)> = recording.iter().collect();
    assert!(
        samples.iter().any(|(t, s)| *t < slowed_ns && s.laser),
        "lit at the point before the loop fell behind"
    );
    let &(at, halves) = recording.underruns.first().expect("an underrun");
    let replayed = at..at + halves as usize * 128;
    let t_underrun = samples[at].0;
    // What the stale halves held was lit (the dwell): the replay is what
    // makes it dark.
    assert!(
        recording
            .stream_runs()
            .any(|(_, _, _, s, generation)| generation.is_none() && s.laser),
        "the replayed content was lit"
    );
    assert!(
        samples[replayed].iter().all(|(_, s)| !s.laser),
        "replay dark"
    );
    // Dark from the moment the DAC reached the unwritten half.
    let lit_after: Vec<_> = samples
        .iter()
        .filter(|(t, s)| *t >= t_underrun && s.laser)
        .collect();
    assert!(
        lit_after.is_empty(),
        "lit after the underrun: {:?}",
        lit_after.first()
    );
    // The loop is still too slow, but holding costs nothing: no underrun
    // once it holds (a jump in flight lands first).
    let quiet_from = t_underrun + 20_000_000;
    let late: Vec<_> = recording
        .underruns
        .iter()
        .filter(|(at, _)| samples[*at].0 > quiet_from)
        .collect();
    assert!(late.is_empty(), "idle underruns: {late:?}");
    assert!(samples.last().expect("samples").0 > quiet_from + 100_000_000);
}

#[test]
fn closing_the_gate_stops_the_loop_even_when_no_stop_request_gets_through() {
    // A full job queue of long dwells; then only the gate closes (no
    // `Stop` request): the loop drops everything, and nothing it had
    // handed to the DAC lights after the close.
    let link: &'static GalvoLink = Box::leak(Box::new(GalvoLink::new()));
    let recording = Rc::new(RefCell::new(DacRecording::default()));
    let gate = laser_sim::laser::recorded_gate(&recording);
    let closed_at = Rc::new(RefCell::new(None));
    let closed = closed_at.clone();
    let dac = SimDac::new(128, 10_000, 0, recording.clone());
    let end = run_loop(dac, link, gate, 5_000_000, async move {
        for seq in 0..5 {
            link.requests
                .send(GalvoRequest::Point {
                    seq,
                    x_mm: 8.0 * seq as f32,
                    y_mm: -5.0,
                    dwell_us: 500_000,
                })
                .await;
        }
        while link.state().1 < 4 {
            embassy_time::Timer::after_millis(1).await;
        }
        embassy_time::Timer::after_millis(20).await;
        *closed.borrow_mut() = Some(embassy_time::Instant::now().as_micros() * 1000);
        gate.close();
        embassy_time::Timer::after_millis(2000).await;
    });
    assert_eq!(end, RunEnd::Stopped);
    assert_eq!(link.state(), (laser_app::galvo::ScanPhase::Idle, 0));
    let closed_ns = closed_at.borrow().expect("closed");
    let recording = recording.borrow().clone();
    let samples: Vec<(u64, DacSample)> = recording.iter().collect();
    assert!(samples.iter().any(|(t, s)| *t < closed_ns && s.laser));
    assert!(samples.iter().all(|(t, s)| *t < closed_ns || !s.laser));
    // The loop itself stopped (not only the gate): its stream is dark
    // from the next half it computed.
    assert!(
        recording
            .stream_runs()
            .all(|(t, _, _, s, _)| t < closed_ns + 3 * 1_280_000 || !s.laser)
    );
}

/// Marks a 40 mm circle with the loop at `sample_period_s`, charged only
/// the Cortex-M4F cost model (`laser_app::galvo::M4_COST`); returns the
/// underruns.
fn mark_circle_at(sample_period_s: f64) -> u32 {
    let link: &'static GalvoLink = Box::leak(Box::new(GalvoLink::new()));
    let recording = Rc::new(RefCell::new(DacRecording::default()));
    let gate = laser_sim::laser::recorded_gate(&recording);
    let period_ns = (sample_period_s * 1e9) as u64;
    let dac = SimDac::new(128, period_ns, 0, recording.clone());
    let config = GalvoConfig {
        sample_period_s,
        ..GalvoConfig::default()
    };
    let circle = laser_app::domain::Figure::Circle {
        centre: laser_app::domain::PointCm::new(0.0, 0.0),
        radius_cm: 4.0,
        rotation: laser_app::domain::Rotation::Ccw,
    };
    run_loop_with(config, dac, link, gate, 2_000_000, async move {
        link.requests
            .send(GalvoRequest::Path {
                seq: 1,
                path: circle,
                mark_speed_mm_s: None,
            })
            .await;
        // Done, refused or an underrun.
        link.events.receive().await;
        embassy_time::Timer::after_millis(5).await;
    });
    link.underruns.load(Ordering::Relaxed)
}

/// The simulator charges what the loop did at the M4's cost: marking
/// costs ≈ 2 µs per sample on the target, so at 1 µs per sample the loop
/// cannot keep up and underruns (as it would on the board), while at the
/// default 10 µs it keeps up with room to spare.
#[test]
fn an_overloaded_loop_underruns_at_the_m4_cost_and_the_default_keeps_up() {
    assert!(mark_circle_at(1e-6) > 0, "1 µs per sample is overloaded");
    assert_eq!(mark_circle_at(10e-6), 0);
}
