//! Joined galvo strokes in the core: one request for consecutive lit
//! blocks, one "done" that frees their queue slots, answers a line that
//! waited for room and moves the position to the stroke's end.

extern crate std;

use crate::domain::{Actuator, Figure};
use crate::galvo::{GalvoEvent, GalvoRequest, MarkStop};
use crate::grbl::realtime::Realtime;
use crate::sequencer::gcode::queue::PLANNER_BLOCKS;
use crate::sequencer::gcode::tests::{closers, line, on, realtime, status};
use crate::sequencer::machine::{Action, Core, Event};
use embassy_time::Instant;
use std::vec::Vec;

/// The galvo requests in `actions`: (seq, stroke segments or `None` for
/// another request, marking speed).
fn galvo_requests(actions: &[Action]) -> Vec<(u32, Option<usize>, Option<f32>)> {
    actions
        .iter()
        .filter_map(|a| match a {
            Action::Galvo(GalvoRequest::Path {
                seq,
                path,
                mark_speed_mm_s,
            }) => {
                let segments = match path {
                    Figure::Stroke(stroke) => Some(stroke.segments()),
                    _ => None,
                };
                Some((*seq, segments, *mark_speed_mm_s))
            }
            Action::Galvo(GalvoRequest::Point { seq, .. }) => Some((*seq, None, None)),
            _ => None,
        })
        .collect()
}

fn done(core: &mut Core, ms: u64, seq: u32) -> Vec<Action> {
    on(core, ms, Event::Galvo(GalvoEvent::Done { seq }))
}

#[test]
fn consecutive_lit_blocks_are_one_stroke_and_finish_together() {
    let mut core = Core::new(Instant::from_millis(0));
    core.actuator = Actuator::Galvo;
    let jump = galvo_requests(&line(&mut core, 1, "G0 X-10 Y-10"));
    let [(jump_seq, None, None)] = jump[..] else {
        panic!("a dark jump: {jump:?}");
    };
    // Three sides of a square and half the fourth, the second side
    // slower; then lit lines to fill the queue.
    for text in [
        "G1 X10 Y-10 F1200 M3 S1000",
        "G1 X10 Y10 F600",
        "G1 X-10 Y10 F1200",
        "G1 X-10 Y0",
    ] {
        assert_eq!(closers(&line(&mut core, 2, text)), 1);
    }
    for k in 4..PLANNER_BLOCKS {
        let text = std::format!("G1 X{} Y-10", k % 2);
        assert_eq!(closers(&line(&mut core, 3, &text)), 1, "line {k} queued");
    }
    assert_eq!(closers(&line(&mut core, 4, "G1 X5 Y5")), 0, "queue full");
    // The jump ends: the square's four G1s go as one stroke at the
    // slowest feed, 600 mm/min, and the lit lines after it as pieces
    // continuing it (two lines each, two ahead); the first leaving the
    // queue makes room for the waiting line.
    let out = done(&mut core, 5, jump_seq);
    assert_eq!(closers(&out), 1, "the waiting line's ok");
    let sent = galvo_requests(&out);
    let [
        (square_seq, Some(4), Some(speed)),
        (b_seq, Some(2), _),
        (c_seq, Some(2), _),
    ] = sent[..]
    else {
        panic!("a four-line stroke and two pieces ahead: {sent:?}");
    };
    assert_eq!(speed, 10.0);
    let continues = |actions: &[Action]| -> Vec<bool> {
        actions
            .iter()
            .filter_map(|a| match a {
                Action::Galvo(GalvoRequest::Path {
                    path: Figure::Stroke(s),
                    ..
                }) => Some(s.continues()),
                _ => None,
            })
            .collect()
    };
    assert_eq!(continues(&out), [false, true, true]);
    assert_eq!(closers(&line(&mut core, 5, "G1 X6 Y6")), 0, "full again");
    assert!(status(&mut core, 6).contains("MPos:-10.000,-10.000,"));
    // Its end frees its slots: the line waiting now is answered, the
    // position is the square's end; the piece sent ahead is in flight
    // (nothing sent again) and one more piece goes ahead.
    let out = done(&mut core, 7, square_seq);
    assert_eq!(closers(&out), 1, "the waiting line's ok");
    let next = galvo_requests(&out);
    assert!(
        matches!(next[..], [(d, Some(2), _)] if d > c_seq),
        "{next:?}"
    );
    let report = status(&mut core, 8);
    assert!(report.contains("MPos:-10.000,0.000,"), "{report}");
    // Each piece's end finishes its two blocks.
    let out = done(&mut core, 9, b_seq);
    assert!(galvo_requests(&out).len() <= 1, "{out:?}");
    let report = status(&mut core, 10);
    assert!(report.contains("MPos:1.000,-10.000,"), "{report}");
    let out = done(&mut core, 11, c_seq);
    let report = status(&mut core, 12);
    assert!(report.contains("MPos:1.000,-10.000,"), "{report} {out:?}");
}

#[test]
fn the_gimbal_and_galvo_together_keep_one_request_per_step() {
    let mut core = Core::new(Instant::from_millis(0));
    core.actuator = Actuator::Both;
    let mut requests = Vec::new();
    for text in ["G1 X1 F600 M3 S1000", "G1 X2", "G1 X3"] {
        requests.extend(galvo_requests(&line(&mut core, 1, text)));
    }
    assert!(
        requests.iter().all(|(_, segments, _)| segments.is_none()),
        "{requests:?}"
    );
}

/// A square (four G1s) and two more lit G1s on the galvo, the jump to it
/// done: the square's stroke and the piece sent ahead, their numbers.
fn square_in_flight(core: &mut Core) -> (u32, u32) {
    core.actuator = Actuator::Galvo;
    let jump = galvo_requests(&line(core, 1, "G0 X-10 Y-10"));
    let [(jump_seq, None, None)] = jump[..] else {
        panic!("a dark jump: {jump:?}");
    };
    for text in [
        "G1 X10 Y-10 F1200 M3 S1000",
        "G1 X10 Y10",
        "G1 X-10 Y10",
        "G1 X-10 Y-10",
        "G1 X0 Y-10",
        "G1 X0 Y0",
    ] {
        assert_eq!(closers(&line(core, 2, text)), 1);
    }
    let sent = galvo_requests(&done(core, 3, jump_seq));
    let [(square, Some(4), _), (ahead, Some(2), _)] = sent[..] else {
        panic!("the square and a piece ahead: {sent:?}");
    };
    (square, ahead)
}

/// The strokes `actions` send: (segments, start cm).
fn strokes(actions: &[Action]) -> Vec<(usize, [f64; 2])> {
    actions
        .iter()
        .filter_map(|a| match a {
            Action::Galvo(GalvoRequest::Path {
                path: Figure::Stroke(s),
                ..
            }) => Some((s.segments(), [s.start().x_cm, s.start().y_cm])),
            _ => None,
        })
        .collect()
}

fn stopped(core: &mut Core, ms: u64, seq: u32, line: u8, at: [f32; 2]) -> Vec<Action> {
    let [x_mm, y_mm] = at;
    let stop = MarkStop {
        seq,
        line,
        x_mm,
        y_mm,
    };
    on(core, ms, Event::Galvo(GalvoEvent::Stopped(Some(stop))))
}

#[test]
fn a_hold_mid_stroke_resumes_from_where_the_galvo_stopped_marking() {
    let mut core = Core::new(Instant::from_millis(0));
    let (square, _) = square_in_flight(&mut core);
    let out = realtime(&mut core, 4, Realtime::FeedHold);
    assert!(out.contains(&Action::CloseGate), "dark at once: {out:?}");
    assert!(status(&mut core, 5).starts_with("<Hold:1"));
    // `~` while stopping waits for the galvo's report.
    assert!(strokes(&realtime(&mut core, 6, Realtime::CycleStart)).is_empty());
    let out = realtime(&mut core, 6, Realtime::FeedHold);
    assert!(strokes(&out).is_empty(), "{out:?}");
    // Stopped on the square's second side, at (10, 0) mm: its first G1
    // is done (a line was waiting for no room: none), held there.
    stopped(&mut core, 7, square, 1, [10.0, 0.0]);
    let report = status(&mut core, 8);
    assert!(report.starts_with("<Hold:0|MPos:10.000,0.000,"), "{report}");
    // `~`: the rest of the second side, the third and fourth, and the
    // next G1 (four lines at most), from the stop point.
    let sent = strokes(&realtime(&mut core, 9, Realtime::CycleStart));
    assert_eq!(sent.first(), Some(&(4, [1.0, 0.0])), "{sent:?}");
}

#[test]
fn a_hold_that_stops_in_the_piece_ahead_finishes_the_stroke_before_it() {
    let mut core = Core::new(Instant::from_millis(0));
    let (square, ahead) = square_in_flight(&mut core);
    realtime(&mut core, 4, Realtime::FeedHold);
    // The square done and the piece ahead (joined) marked to half its
    // second line, (0, -5) mm.
    assert_ne!(square, ahead);
    stopped(&mut core, 7, ahead, 1, [0.0, -5.0]);
    let report = status(&mut core, 8);
    assert!(report.starts_with("<Hold:0|MPos:0.000,-5.000,"), "{report}");
    let sent = strokes(&realtime(&mut core, 9, Realtime::CycleStart));
    assert_eq!(sent, [(1, [0.0, -0.5])]);
}

#[test]
fn a_hold_the_galvo_caught_before_marking_redoes_the_stroke() {
    let mut core = Core::new(Instant::from_millis(0));
    square_in_flight(&mut core);
    realtime(&mut core, 4, Realtime::FeedHold);
    // Nothing of it was lit: held where it was, all of it marked on `~`.
    on(&mut core, 5, Event::Galvo(GalvoEvent::Stopped(None)));
    let report = status(&mut core, 6);
    assert!(
        report.starts_with("<Hold:0|MPos:-10.000,-10.000,"),
        "{report}"
    );
    let sent = strokes(&realtime(&mut core, 7, Realtime::CycleStart));
    assert_eq!(sent.first(), Some(&(4, [-1.0, -1.0])), "{sent:?}");
}

#[test]
fn a_soft_reset_while_the_galvo_stops_is_alarm_3_and_its_late_report_is_ignored() {
    let texts = |out: &[Action]| std::format!("{out:?}");
    // Still braking (no report yet): motion was interrupted.
    let mut core = Core::new(Instant::from_millis(0));
    let (square, _) = square_in_flight(&mut core);
    realtime(&mut core, 4, Realtime::FeedHold);
    let out = realtime(&mut core, 5, Realtime::SoftReset);
    assert!(texts(&out).contains("ALARM:3"), "{out:?}");
    let out = stopped(&mut core, 6, square, 1, [10.0, 0.0]);
    assert!(strokes(&out).is_empty(), "{out:?}");
    assert!(!status(&mut core, 7).contains("MPos:10.000,0.000,"));
    // Held (the report came): at rest, no alarm.
    let mut core = Core::new(Instant::from_millis(0));
    let (square, _) = square_in_flight(&mut core);
    realtime(&mut core, 4, Realtime::FeedHold);
    stopped(&mut core, 5, square, 1, [10.0, 0.0]);
    let out = realtime(&mut core, 6, Realtime::SoftReset);
    assert!(!texts(&out).contains("ALARM:3"), "{out:?}");
}
