//! Joined galvo strokes in the core: one request for consecutive lit
//! blocks, one "done" that frees their queue slots, answers a line that
//! waited for room and moves the position to the stroke's end.

extern crate std;

use std::vec::Vec;

use embassy_time::Instant;

use super::super::gcode::tests::{closers, line, on, status};
use super::super::gcode_motion::PLANNER_BLOCKS;
use super::super::machine::{Action, Core, Event};
use crate::domain::{Actuator, Figure};
use crate::galvo::{GalvoEvent, GalvoRequest};

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
