//! Tests of the feed override on the fly: the cruise rate follows the new
//! override within a few segments, and no rate change exceeds the
//! acceleration limit.

extern crate std;

use super::motion_tests::{Event, accel_bounded, arb_move, cases, run_acting};
use super::*;
use proptest::prelude::*;
use std::vec::Vec;

/// Runs `moves` at their rate as a programmed feed (all queued at once),
/// sets the feed override `scale` after `at` step events (rates capped at
/// `max_rate`), and runs to the end.
fn run_with_override(
    moves: &[StepMove],
    jd: f64,
    at: usize,
    scale: f64,
    max_rate: f64,
) -> Vec<Event> {
    run_acting(moves, jd, true, at, |prep, planner, _, _| {
        prep.set_feed_scale(scale, max_rate, planner)
    })
}

proptest! {
    #![proptest_config(cases(256))]

    /// An override at any point, up or down: every step of every block
    /// runs, the rate never changes faster than the limit allows, and it
    /// ends at rest.
    #[test]
    fn override_keeps_the_acceleration_limit(
        first in arb_move(),
        more in prop::collection::vec(arb_move(), 0..3),
        jd in 0.0f64..20.0,
        at in 0usize..3000,
        scale in 0.1f64..2.0,
    ) {
        let accel = first.accel_steps_per_s2;
        let moves: Vec<StepMove> = core::iter::once(first)
            .chain(more)
            .map(|m| StepMove { accel_steps_per_s2: accel, ..m })
            .collect();
        let events = run_with_override(&moves, jd, at, scale, 40_000.0);
        let total: usize = moves
            .iter()
            .map(|m| m.steps[0].unsigned_abs().max(m.steps[1].unsigned_abs()) as usize)
            .sum();
        prop_assert_eq!(events.len(), total);
        accel_bounded(&events, &std::vec![accel; events.len()])?;
        if let Some(last) = events.last() {
            prop_assert!(last.rate <= libm::sqrt(accel / 2.0) * 1.5 + 1.0);
        }
    }
}

/// A long move cruising at 800 steps/s: 50 % mid-move brings the cruise
/// to 400 within the braking time and the prepared segments; 150 % to
/// 1200.
#[test]
fn override_changes_the_cruise_mid_block() {
    let mv = StepMove {
        steps: [6000, 1000],
        nominal_rate_steps_per_s: 800.0,
        accel_steps_per_s2: 16_000.0,
    };
    for (scale, want) in [(0.5, 400.0), (1.5, 1200.0)] {
        let events = run_with_override(&[mv], 0.0, 2000, scale, 40_000.0);
        // Before: cruising at 800.
        assert!(
            (events[1990].rate - 800.0).abs() < 2.0,
            "{}",
            events[1990].rate
        );
        // v change / a = 25 ms ≈ 10–30 events, 4 prepared segments ≈ 4
        // events: at the new cruise 60 events later.
        let after = events[2060].rate;
        assert!((after - want).abs() < want * 0.01, "{scale}: {after}");
    }
}
