extern crate std;

use std::vec;
use std::vec::Vec;

use kinematics_core::Galvo;

use super::super::{GalvoConfig, GalvoLoop};
use crate::domain::{Figure, PointCm, StrokeCm};
use crate::galvo::{DacSample, GalvoEvent, GalvoRequest};

/// A stroke through `xs` (mm) along y = 0, continuing the one before it
/// when `continues`.
fn piece(seq: u32, xs: &[f64], continues: bool) -> GalvoRequest {
    let at = |x_mm: f64| PointCm::new(x_mm / 10.0, 0.0);
    let mut stroke = if continues {
        StrokeCm::continuing(at(xs[0]))
    } else {
        StrokeCm::new(at(xs[0]))
    }
    .unwrap();
    for &x in &xs[1..] {
        assert!(stroke.line_to(at(x)));
    }
    GalvoRequest::Path {
        seq,
        path: Figure::Stroke(stroke),
        mark_speed_mm_s: None,
    }
}

/// Runs the loop as its task does (one prep step, then the refill, per
/// 128-sample half), sending `later` once the event `after` was
/// reported `delay` halves ago; returns the samples and the events with
/// the half they came in.
fn run_halves(
    galvo: &mut GalvoLoop,
    mut later: Vec<(u32, u32, GalvoRequest)>,
    until: u32,
) -> (Vec<DacSample>, Vec<(usize, GalvoEvent)>) {
    let mut samples = Vec::new();
    let mut events: Vec<(usize, GalvoEvent)> = Vec::new();
    let mut half = [DacSample::default(); 128];
    for k in 0..2_000 {
        if events
            .iter()
            .any(|(_, e)| *e == GalvoEvent::Done { seq: until })
        {
            break;
        }
        later.retain(|(after, delay, request)| {
            let due = events
                .iter()
                .any(|(at, e)| *e == GalvoEvent::Done { seq: *after } && at + *delay as usize <= k);
            if due {
                assert_eq!(galvo.request(*request), None);
            }
            !due
        });
        galvo.prep_up_to(1);
        let mut local = Vec::new();
        galvo.refill(&mut half, |e| local.push(e));
        events.extend(local.into_iter().map(|e| (k, e)));
        samples.extend_from_slice(&half);
    }
    (samples, events)
}

fn x_mm(s: &DacSample) -> f64 {
    Galvo::<f64>::default()
        .codes_to_board(s.x_code, s.y_code)
        .unwrap()
        .x_mm
}

#[test]
fn pieces_continuing_a_stroke_are_marked_as_one_stroke_without_a_stop() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    // A straight 80 mm line in ten 8 mm lines: four, then three pieces
    // of two continuing it, the last sent only three halves after the
    // first piece is reported done (as the sequencer would).
    let x = |k: usize| -40.0 + 8.0 * k as f64;
    let xs: Vec<f64> = (0..=10).map(x).collect();
    for request in [
        piece(1, &xs[0..=4], false),
        piece(2, &xs[4..=6], true),
        piece(3, &xs[6..=8], true),
    ] {
        assert_eq!(galvo.request(request), None);
    }
    let (samples, events) = run_halves(&mut galvo, vec![(1, 3, piece(4, &xs[8..=10], true))], 4);
    let done: Vec<u32> = events
        .iter()
        .filter_map(|(_, e)| match e {
            GalvoEvent::Done { seq } => Some(*seq),
            _ => None,
        })
        .collect();
    assert_eq!(done, [1, 2, 3, 4], "{events:?}");
    // One laser on/off pair.
    let ons = samples
        .windows(2)
        .filter(|w| w[1].laser && !w[0].laser)
        .count();
    assert_eq!(ons, 1);
    // No stop at the joints (x = -8, 8, 24 mm): the 60 mm from -30 to
    // 30 mm at the marking speed, 1000 mm/s, is 6 000 samples (a stop
    // from 1000 mm/s at 1e5 mm/s² and back adds 2 000).
    let middle = samples
        .iter()
        .filter(|s| s.laser && (-30.0..=30.0).contains(&x_mm(s)))
        .count();
    assert!((6_000..6_100).contains(&middle), "{middle} samples");
    let last = samples.iter().rposition(|s| s.laser).unwrap();
    assert!((x_mm(&samples[last]) - 40.0).abs() < 0.15);
}

#[test]
fn a_piece_that_comes_after_the_stroke_ended_is_a_stroke_of_its_own() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    let xs = [-20.0, -10.0, 0.0, 10.0];
    assert_eq!(galvo.request(piece(1, &xs[0..=2], false)), None);
    // Sent 20 halves (25.6 ms) after the first is done: it ended dark.
    let later = vec![(1, 20, piece(2, &xs[2..=3], true))];
    let (samples, events) = run_halves(&mut galvo, later, 2);
    assert_eq!(events.len(), 2, "{events:?}");
    let ons = samples
        .windows(2)
        .filter(|w| w[1].laser && !w[0].laser)
        .count();
    assert_eq!(ons, 2);
    let lit: Vec<f64> = samples.iter().filter(|s| s.laser).map(x_mm).collect();
    assert!(lit.iter().all(|x| (-20.15..10.15).contains(x)));
}

#[test]
fn stop_mid_contour_drops_the_joined_pieces_and_brakes_dark() {
    let mut galvo = GalvoLoop::new(GalvoConfig::default()).unwrap();
    let xs: Vec<f64> = (0..=8).map(|k| -40.0 + 10.0 * f64::from(k)).collect();
    for request in [
        piece(1, &xs[0..=4], false),
        piece(2, &xs[4..=6], true),
        piece(3, &xs[6..=8], true),
    ] {
        assert_eq!(galvo.request(request), None);
    }
    let mut half = [DacSample::default(); 128];
    let mut events = Vec::new();
    // Into the second piece (x 0 to 20 mm).
    for _ in 0..40 {
        galvo.prep_up_to(1);
        galvo.refill(&mut half, |e| events.push(e));
    }
    assert!(half.iter().all(|s| s.laser), "marking");
    assert!(
        (0.0..20.0).contains(&x_mm(&half[127])),
        "{}",
        x_mm(&half[127])
    );
    assert_eq!(galvo.request(GalvoRequest::Stop), None);
    galvo.prep_up_to(1);
    galvo.refill(&mut half, |e| events.push(e));
    assert!(half.iter().all(|s| !s.laser), "dark from the stop on");
    for _ in 0..100 {
        galvo.prep_up_to(1);
        galvo.refill(&mut half, |e| events.push(e));
        assert!(half.iter().all(|s| !s.laser));
    }
    // Only the first piece was reached before the stop.
    assert_eq!(events, [GalvoEvent::Done { seq: 1 }]);
    assert!(galvo.hold_sample().is_some(), "holding");
}
