//! Tests of the feed hold: a stop mid-move decelerates at the limit along
//! the path, to rest, and drops what is left.

extern crate std;

use super::motion_tests::{Event, SEGMENT_S, TIMER_HZ, accel_bounded, arb_move, cases, run_acting};
use super::*;
use proptest::prelude::*;
use std::vec::Vec;

/// Runs `moves` (all queued at once), holds after `hold_after` step events
/// (`now`: taking the prepared segments back, [`SegmentPrep::hold_now`];
/// else after them, [`SegmentPrep::hold`]) and runs to rest. Returns the
/// events and the events at the hold.
fn run_with_hold(moves: &[StepMove], jd: f64, hold_after: usize, now: bool) -> (Vec<Event>, usize) {
    let events = run_acting(
        moves,
        jd,
        false,
        hold_after,
        |prep, planner, queue, generator| {
            if now {
                prep.hold_now(planner, generator.executing(), queue);
            } else {
                prep.hold(planner);
            }
        },
    );
    let held = hold_after.min(events.len());
    (events, held)
}

proptest! {
    #![proptest_config(cases(256))]

    /// After a hold: at most the prepared segments run at their rates,
    /// then the rate only falls, never faster than the limit, and ends at
    /// rest; the steps stay on each block's line.
    #[test]
    fn hold_decelerates_within_the_limit_to_rest(
        first in arb_move(),
        more in prop::collection::vec(arb_move(), 0..3),
        jd in 0.0f64..20.0,
        hold_after in 0usize..3000,
        now in any::<bool>(),
    ) {
        let accel = first.accel_steps_per_s2;
        let moves: Vec<StepMove> = core::iter::once(first)
            .chain(more)
            .map(|m| StepMove { accel_steps_per_s2: accel, ..m })
            .collect();
        let (events, held) = run_with_hold(&moves, jd, hold_after, now);
        let limits = std::vec![accel; events.len()];
        accel_bounded(&events, &limits)?;
        if let Some(last) = events.last() {
            prop_assert!(last.rate <= libm::sqrt(accel / 2.0) * (1.0 + 1e-9));
        }
        // Past the segments prepared before the hold (≤ 4 + 1 in the
        // generator; with `now` only the one running), the rate never
        // rises again.
        let prepared = if now { 1 } else { 5 };
        if now && held > 0 && held < events.len() {
            // The running segment's rest, then at most v²/2a to rest.
            let v = events[held - 1].rate;
            let bound = v * SEGMENT_S + 1.0 + libm::ceil(v * v / (2.0 * accel)) + 1.0;
            let after = (events.len() - held) as f64;
            prop_assert!(after <= bound, "{after} events after the hold at {v} steps/s");
        }
        let mut segments = 0;
        let mut peak = f64::INFINITY;
        for w in events[held.min(events.len())..].windows(2) {
            if w[1].tick.period_ticks != w[0].tick.period_ticks {
                segments += 1;
            }
            if segments > prepared {
                prop_assert!(w[1].rate <= peak * (1.0 + 1e-9), "{} after {}", w[1].rate, peak);
                peak = peak.min(w[1].rate);
            }
        }
        let total: usize = moves.iter().map(|m| m.steps[0].unsigned_abs().max(m.steps[1].unsigned_abs()) as usize).sum();
        prop_assert!(events.len() <= total);
    }
}

/// The seed's 90° pan at 30 °/s, held after a second: stops well short
/// of the end, from cruise, in about v²/2a steps.
#[test]
fn hold_mid_cruise_stops_short() {
    let mv = StepMove {
        steps: [1600, 400],
        nominal_rate_steps_per_s: 533.0,
        accel_steps_per_s2: 1000.0,
    };
    let (events, held) = run_with_hold(&[mv], 0.0, 700, false);
    assert_eq!(held, 700);
    // v²/2a = 142 steps of deceleration after ≤ 5 prepared segments
    // (≤ 4 events each at 533 steps/s and 1.5 ms).
    let after = events.len() - held;
    assert!((142..=142 + 25).contains(&after), "{after}");
    // Braking at once: the running segment's rest (≤ 1 event), then
    // v²/2a.
    let (events, held) = run_with_hold(&[mv], 0.0, 700, true);
    let after = events.len() - held;
    assert!((142..=142 + 2).contains(&after), "{after}");
    // Still on the block's line: tilt is a quarter of pan, within a step.
    let pan = events.iter().filter(|e| e.tick.step[0]).count() as f64;
    let tilt = events.iter().filter(|e| e.tick.step[1]).count() as f64;
    assert!((tilt - pan / 4.0).abs() <= 1.0, "{pan} {tilt}");
    // A hold at rest does nothing; a new move runs after it.
    let mut planner: Planner<2> = Planner::new(0.0).unwrap();
    let mut prep = SegmentPrep::new(TIMER_HZ, SEGMENT_S).unwrap();
    prep.hold(&mut planner);
    assert!(!prep.is_holding());
    planner.push(&mv).unwrap();
    assert!(prep.next_segment(&mut planner).is_some());
}
