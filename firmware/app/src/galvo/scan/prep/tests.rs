extern crate std;

use std::vec::Vec;

use super::super::{GalvoConfig, GalvoLoop, ScanPhase};
use crate::domain::{Figure, PointCm, Rotation};
use crate::galvo::{DacSample, GalvoEvent, GalvoRequest};

/// Every sample and event of a loop driven in 128-sample halves, the
/// requests handed over between halves as the queue takes them.
/// `prepared`: [`GalvoLoop::prep`] then [`GalvoLoop::refill`] per half (as
/// `GalvoLoop::run` does); otherwise [`GalvoLoop::fill`], planning on
/// demand.
fn drive(
    requests: &[GalvoRequest],
    prepared: bool,
) -> (Vec<DacSample>, Vec<(usize, GalvoEvent)>, GalvoLoop) {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    let (mut samples, mut events) = (Vec::new(), Vec::new());
    let mut pending = requests.iter().copied().peekable();
    let mut half = [DacSample::default(); 128];
    for _ in 0..2000 {
        while let Some(&request) = pending.peek() {
            match galvo.request(request) {
                Some(GalvoEvent::Refused { .. }) => break,
                _ => {
                    pending.next();
                }
            }
        }
        let base = samples.len();
        let mut on_event = |e| events.push((base, e));
        if prepared {
            galvo.prep();
            galvo.refill(&mut half, &mut on_event);
        } else {
            galvo.fill(&mut half, &mut on_event);
        }
        samples.extend_from_slice(&half);
        if pending.peek().is_none()
            && galvo.phase() == ScanPhase::Idle
            && galvo.queued_points() == 0
        {
            break;
        }
    }
    (samples, events, galvo)
}

fn point(seq: u32, x_mm: f32, y_mm: f32, dwell_us: u32) -> GalvoRequest {
    GalvoRequest::Point {
        seq,
        x_mm,
        y_mm,
        dwell_us,
    }
}

#[test]
fn prepared_refills_output_what_planning_on_demand_does() {
    let requests = [
        point(1, 60.0, -35.0, 0),
        point(2, 60.5, -35.0, 0),
        point(3, -80.0, 80.0, 200),
        GalvoRequest::Path {
            seq: 4,
            mark_speed_mm_s: None,
            // Centre (10, -5) mm, half size 25 mm.
            path: Figure::Tuning {
                centre: PointCm::new(1.0, -0.5),
                size_cm: 5.0,
            },
        },
        point(5, 0.0, 0.0, 0),
        GalvoRequest::Path {
            seq: 6,
            mark_speed_mm_s: None,
            // Centre (-20, 10) mm, radius 3 mm.
            path: Figure::Circle {
                centre: PointCm::new(-2.0, 1.0),
                radius_cm: 0.3,
                rotation: Rotation::Cw,
            },
        },
        GalvoRequest::Path {
            seq: 7,
            mark_speed_mm_s: None,
            // (-5, 5) mm to (5, -5) mm.
            path: Figure::Rect {
                a: PointCm::new(-0.5, 0.5),
                b: PointCm::new(0.5, -0.5),
            },
        },
        point(8, 1.0, 1.0, 0),
        point(9, 1.0, 1.5, 0),
        point(10, 1.5, 1.5, 0),
    ];
    let (on_demand, on_demand_events, _) = drive(&requests, false);
    let (prepared, prepared_events, galvo) = drive(&requests, true);
    assert_eq!(
        on_demand_events
            .iter()
            .filter(|(_, e)| matches!(e, GalvoEvent::Done { .. }))
            .count(),
        requests.len()
    );
    // The steps chain exactly (each planned from where the one before
    // leaves the mirrors), so the refill never waited and never re-planned.
    assert_eq!(galvo.unprepared_samples(), 0);
    assert_eq!(prepared_events, on_demand_events);
    assert_eq!(prepared.len(), on_demand.len());
    assert!(prepared == on_demand, "same samples, sample for sample");
}

#[test]
fn a_refill_without_a_prepared_step_holds_dark_and_counts_it() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    assert_eq!(galvo.request(point(1, 40.0, 20.0, 300)), None);
    let mut half = [DacSample::default(); 128];
    let mut events = Vec::new();
    galvo.refill(&mut half, |e| events.push(e));
    let centre = half[0];
    assert!(
        half.iter().all(|s| *s == centre && !s.laser),
        "held dark at the centre"
    );
    assert_eq!(galvo.unprepared_samples(), 128);
    assert_eq!(galvo.queued_points(), 1, "the job waits for its plan");
    assert!(events.is_empty());

    // Prepared, the next refill runs it; nothing more is counted.
    assert_eq!(galvo.prep(), 1);
    let mut lit = 0;
    for _ in 0..40 {
        galvo.prep();
        galvo.refill(&mut half, |e| events.push(e));
        lit += half.iter().filter(|s| s.laser).count();
    }
    assert_eq!(events, [GalvoEvent::Done { seq: 1 }]);
    assert_eq!(lit, 30, "300 µs dwell at 10 µs");
    assert_eq!(galvo.unprepared_samples(), 128);
}

#[test]
fn stop_drops_the_prepared_steps() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    galvo.request(point(1, 40.0, 20.0, 300));
    galvo.request(point(2, -40.0, 20.0, 300));
    assert_eq!(galvo.prep(), 2);
    galvo.stop();
    let mut half = [DacSample::default(); 128];
    let mut events = Vec::new();
    galvo.refill(&mut half, |e| events.push(e));
    assert!(half.iter().all(|s| !s.laser));
    assert_eq!(galvo.phase(), ScanPhase::Idle);
    assert!(events.is_empty());
    assert_eq!(galvo.prep(), 0, "nothing left to prepare");
}
