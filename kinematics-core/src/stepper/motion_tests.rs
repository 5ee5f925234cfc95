//! Tests of the stepper motion pipeline: planner → segment prep → step
//! generator, run on a simulated step timer.

extern crate std;

use super::*;
use crate::stepper::StepperAxis;
use proptest::prelude::*;
use std::vec::Vec;

pub(super) const TIMER_HZ: u32 = 1_000_000;

/// Property-test configuration with `default` cases, or `PROPTEST_CASES`
/// when set (for stress runs: `PROPTEST_CASES=5000`).
pub(super) fn cases(default: u32) -> ProptestConfig {
    let n = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default);
    ProptestConfig {
        cases: n,
        ..ProptestConfig::default()
    }
}
pub(super) const SEGMENT_S: f64 = 0.0015;

/// One executed step event: the tick, with the time it lasted.
#[derive(Debug, Clone, Copy)]
pub(super) struct Event {
    pub(super) tick: StepTick,
    /// Rate of the segment the event belongs to, events/s.
    pub(super) rate: f64,
}

/// Runs `moves` (all queued at once; as programmed feeds at their rate
/// when `feed`) through the whole pipeline, calls `act` on the prep, the
/// planner, the step queue and the generator once `at` step events have
/// run, and runs to rest. Returns every step event.
pub(super) fn run_acting(
    moves: &[StepMove],
    jd: f64,
    feed: bool,
    at: usize,
    mut act: impl FnMut(&mut SegmentPrep, &mut Planner<16>, &mut SegmentQueue<4>, &StepGenerator),
) -> Vec<Event> {
    let mut planner: Planner<16> = Planner::new(jd).unwrap();
    for mv in moves {
        let rate = if feed {
            mv.nominal_rate_steps_per_s
        } else {
            0.0
        };
        planner.push_feed(mv, rate).unwrap();
    }
    let mut prep = SegmentPrep::new(TIMER_HZ, SEGMENT_S).unwrap();
    let mut queue: SegmentQueue<4> = SegmentQueue::default();
    let mut generator = StepGenerator::new();
    let mut events = Vec::new();
    loop {
        if events.len() == at {
            act(&mut prep, &mut planner, &mut queue, &generator);
        }
        prep.fill(&mut planner, &mut queue);
        let Some(tick) = generator.tick(&mut queue) else {
            break;
        };
        events.push(Event {
            tick,
            rate: f64::from(TIMER_HZ) / f64::from(tick.period_ticks),
        });
    }
    assert!(planner.is_empty());
    assert!(!prep.is_holding() && !prep.is_busy());
    events
}

/// Runs `moves` through the whole pipeline, pushing each move after
/// `prep_between` prep/tick rounds, and returns every step event.
fn run(moves: &[StepMove], jd_steps: f64, prep_between: usize) -> Vec<Event> {
    let mut planner: Planner<16> = Planner::new(jd_steps).unwrap();
    let mut prep = SegmentPrep::new(TIMER_HZ, SEGMENT_S).unwrap();
    let mut queue: SegmentQueue<4> = SegmentQueue::default();
    let mut generator = StepGenerator::new();
    let mut events = Vec::new();
    let mut tick_round = |planner: &mut Planner<16>, events: &mut Vec<Event>| {
        prep.fill(planner, &mut queue);
        let t = generator.tick(&mut queue)?;
        events.push(Event {
            tick: t,
            rate: f64::from(TIMER_HZ) / f64::from(t.period_ticks),
        });
        Some(())
    };
    for mv in moves {
        planner.push(mv).unwrap();
        for _ in 0..prep_between {
            tick_round(&mut planner, &mut events);
        }
    }
    while tick_round(&mut planner, &mut events).is_some() {}
    assert!(planner.is_empty());
    events
}

fn events_of(mv: &StepMove) -> usize {
    mv.steps[0].unsigned_abs().max(mv.steps[1].unsigned_abs()) as usize
}

pub(super) fn arb_move() -> impl Strategy<Value = StepMove> {
    (
        (-1500i32..1500, -1500i32..1500),
        1.0f64..20_000.0,
        1.0f64..200_000.0,
    )
        .prop_filter("moves", |((x, y), _, _)| *x != 0 || *y != 0)
        .prop_map(|((x, y), rate, accel)| StepMove {
            steps: [x, y],
            nominal_rate_steps_per_s: rate,
            accel_steps_per_s2: accel,
        })
}

/// Random move sequences where about half the moves continue straight on
/// in the previous direction, short (1/50 of it): fast junctions followed
/// by short blocks, which only the reverse pass can make stop in time.
fn arb_moves() -> impl Strategy<Value = Vec<StepMove>> {
    prop::collection::vec((arb_move(), any::<bool>()), 1..6).prop_map(|picks| {
        let mut moves: Vec<StepMove> = Vec::new();
        for (mut mv, straight) in picks {
            if let Some(prev) = moves.last().filter(|_| straight) {
                let short = [prev.steps[0] / 50, prev.steps[1] / 50];
                if short != [0, 0] {
                    mv.steps = short;
                }
            }
            moves.push(mv);
        }
        moves
    })
}

/// Splits the events into the blocks' windows.
fn windows<'a>(moves: &[StepMove], events: &'a [Event]) -> Vec<&'a [Event]> {
    let mut out = Vec::new();
    let mut start = 0;
    for mv in moves {
        let n = events_of(mv);
        out.push(&events[start..start + n]);
        start += n;
    }
    assert_eq!(start, events.len(), "one event per dominant-axis step");
    out
}

/// Between segments the rate changes no faster than the acceleration
/// limit (`limits[i]` for event `i`) allows, plus one period's rounding.
pub(super) fn accel_bounded(events: &[Event], limits: &[f64]) -> Result<(), TestCaseError> {
    let mut prev: Option<(f64, f64)> = None; // (rate, segment time)
    let mut i = 0;
    while i < events.len() {
        let rate = events[i].rate;
        let mut j = i;
        while j < events.len() && events[j].tick.period_ticks == events[i].tick.period_ticks {
            j += 1;
        }
        let dt = (j - i) as f64 / rate;
        if let Some((r0, dt0)) = prev {
            let a = limits[i].max(limits[i - 1]);
            let quant = (r0 * r0 + rate * rate) / f64::from(TIMER_HZ);
            prop_assert!(
                (rate - r0).abs() <= a * (dt0 + dt) / 2.0 * (1.0 + 1e-6) + quant + 1e-9,
                "rate {} -> {} over {} s at {}",
                r0,
                rate,
                dt0 + dt,
                a
            );
        }
        prev = Some((rate, dt));
        i = j;
    }
    Ok(())
}

proptest! {
    #![proptest_config(cases(256))]

    /// Every block's steps come out exactly, per axis and direction, and
    /// each axis stays within half a step of the block's straight line.
    #[test]
    fn steps_exact_and_on_the_line(
        moves in arb_moves(),
        jd in 0.0f64..20.0,
        between in 0usize..300,
    ) {
        let events = run(&moves, jd, between);
        for (mv, win) in moves.iter().zip(windows(&moves, &events)) {
            let n = win.len() as f64;
            let mut pos = [0i64; 2];
            for (k, e) in win.iter().enumerate() {
                for (axis, p) in pos.iter_mut().enumerate() {
                    if e.tick.step[axis] {
                        *p += if e.tick.negative[axis] { -1 } else { 1 };
                    }
                    let ideal = f64::from(mv.steps[axis]) * (k + 1) as f64 / n;
                    prop_assert!((*p as f64 - ideal).abs() <= 0.5 + 1e-9, "axis {} event {}: {} vs {}", axis, k, p, ideal);
                }
            }
            prop_assert_eq!(pos, [i64::from(mv.steps[0]), i64::from(mv.steps[1])]);
        }
    }

    /// The rate never exceeds the block's nominal rate, starts and ends at
    /// rest, and between segments changes no faster than the acceleration
    /// limit allows (plus one period's rounding).
    #[test]
    fn rates_and_acceleration_bounded(
        moves in arb_moves(),
        jd in 0.0f64..20.0,
        between in 0usize..300,
    ) {
        let events = run(&moves, jd, between);
        let mut limits = Vec::new();
        for (mv, win) in moves.iter().zip(windows(&moves, &events)) {
            for e in win {
                prop_assert!(e.rate <= mv.nominal_rate_steps_per_s * (1.0 + 1e-9));
                limits.push(mv.accel_steps_per_s2);
            }
        }
        let a_first = moves[0].accel_steps_per_s2;
        let a_last = moves[moves.len() - 1].accel_steps_per_s2;
        // From rest over the first event: mean rate √(a/2).
        prop_assert!(events[0].rate <= libm::sqrt(a_first / 2.0) * (1.0 + 1e-9));
        prop_assert!(events[events.len() - 1].rate <= libm::sqrt(a_last / 2.0) * (1.0 + 1e-9));
        accel_bounded(&events, &limits)?;
    }

    /// The planned entry of a junction never exceeds grbl's deviation
    /// limit nor either block's nominal rate.
    #[test]
    fn junction_rule_respected(a in arb_move(), b in arb_move(), jd in 0.0f64..20.0) {
        let mut planner: Planner<4> = Planner::new(jd).unwrap();
        planner.push(&a).unwrap();
        planner.push(&b).unwrap();
        let unit = |m: &StepMove| {
            let n = libm::hypot(f64::from(m.steps[0]), f64::from(m.steps[1]));
            [f64::from(m.steps[0]) / n, f64::from(m.steps[1]) / n]
        };
        let accel = a.accel_steps_per_s2.min(b.accel_steps_per_s2);
        let limit = junction_rate_steps_per_s(unit(&a), unit(&b), accel, jd);
        let first = planner.pop().unwrap();
        prop_assert_eq!(first.entry_rate_steps_per_s, 0.0);
        prop_assert!(first.exit_rate_steps_per_s <= limit);
        prop_assert!(first.exit_rate_steps_per_s <= a.nominal_rate_steps_per_s);
        prop_assert!(first.exit_rate_steps_per_s <= b.nominal_rate_steps_per_s);
        let second = planner.pop().unwrap();
        prop_assert_eq!(second.entry_rate_steps_per_s, first.exit_rate_steps_per_s);
        prop_assert_eq!(second.exit_rate_steps_per_s, 0.0);
    }

    /// Any input, however bad, gives a value or a clear error.
    #[test]
    fn no_panic_on_any_input(x in any::<i32>(), y in any::<i32>(), r in any::<f64>(), a in any::<f64>(), jd in any::<f64>()) {
        if let Ok(mut planner) = Planner::<2>::new(jd) {
            let mv = StepMove { steps: [x, y], nominal_rate_steps_per_s: r, accel_steps_per_s2: a };
            if planner.push(&mv).is_ok() {
                let b = planner.pop();
                prop_assert!(b.is_none_or(|b| b.entry_rate_steps_per_s.is_finite()));
            }
        }
    }
}

/// The seed's axis: 90° of pan is 1600 microsteps; at 30 °/s
/// (533.33 steps/s) and 1000 steps/s² the trapezoid takes
/// d/v + v/a = 3.0 s + 0.5333 s.
#[test]
fn seed_known_answer() {
    let axis = StepperAxis::default();
    assert_eq!(axis.deg_per_step, 0.05625);
    let steps = axis.angle_to_steps(90.0).unwrap();
    assert_eq!(steps, 1600);
    let rate = 30.0 / axis.deg_per_step;
    let mv = StepMove {
        steps: [steps, 0],
        nominal_rate_steps_per_s: rate,
        accel_steps_per_s2: 1000.0,
    };
    let events = run(&[mv], 0.0, 0);
    assert_eq!(events.len(), 1600);
    assert!(
        events
            .iter()
            .all(|e| e.tick.step == [true, false] && e.tick.negative == [false, false])
    );
    let total_s: f64 = events
        .iter()
        .map(|e| f64::from(e.tick.period_ticks))
        .sum::<f64>()
        / f64::from(TIMER_HZ);
    let expected_s = 1600.0 / rate + rate / 1000.0;
    // Rounding each period up by < 1 µs over 1600 events: < 1.6 ms.
    assert!(
        total_s >= expected_s - 1e-9 && total_s < expected_s + 1.6e-3,
        "{total_s} vs {expected_s}"
    );
    let peak = events.iter().map(|e| e.rate).fold(0.0, f64::max);
    assert!(peak <= rate && peak > rate * 0.99, "{peak}");
}

/// grbl's rule at a right angle: v² = a·δ·sin45°/(1 − sin45°).
#[test]
fn junction_known_answers() {
    let v = junction_rate_steps_per_s([1.0, 0.0], [0.0, 1.0], 1000.0, 1.0);
    assert!((v - 49.134_9).abs() < 1e-3, "{v}");
    assert_eq!(
        junction_rate_steps_per_s([1.0, 0.0], [-1.0, 0.0], 1000.0, 1.0),
        0.0
    );
    assert_eq!(
        junction_rate_steps_per_s([1.0, 0.0], [1.0, 0.0], 1000.0, 1.0),
        f64::INFINITY
    );
    // A straight continuation cruises through at the nominal rate.
    let mut planner: Planner<4> = Planner::new(1.0).unwrap();
    let mv = StepMove {
        steps: [1000, 0],
        nominal_rate_steps_per_s: 100.0,
        accel_steps_per_s2: 1000.0,
    };
    planner.push(&mv).unwrap();
    planner.push(&mv).unwrap();
    assert_eq!(planner.pop().unwrap().exit_rate_steps_per_s, 100.0);
}

#[test]
fn bad_input_is_refused_and_changes_nothing() {
    let good = StepMove {
        steps: [10, 5],
        nominal_rate_steps_per_s: 100.0,
        accel_steps_per_s2: 100.0,
    };
    let mut planner: Planner<1> = Planner::new(1.0).unwrap();
    for (rate, accel, err) in [
        (f64::NAN, 100.0, MotionError::InvalidRate),
        (0.0, 100.0, MotionError::InvalidRate),
        (-5.0, 100.0, MotionError::InvalidRate),
        (f64::INFINITY, 100.0, MotionError::InvalidRate),
        (100.0, f64::NAN, MotionError::InvalidAccel),
        (100.0, 0.5, MotionError::InvalidAccel),
    ] {
        let mv = StepMove {
            nominal_rate_steps_per_s: rate,
            accel_steps_per_s2: accel,
            ..good
        };
        assert_eq!(planner.push(&mv), Err(err));
    }
    let long = StepMove {
        steps: [i32::MIN, 0],
        ..good
    };
    assert_eq!(planner.push(&long), Err(MotionError::MoveTooLong));
    assert!(planner.is_empty());
    planner.push(&good).unwrap();
    assert_eq!(planner.push(&good), Err(MotionError::QueueFull));
    assert_eq!(planner.len(), 1);
    // A zero move is accepted and ignored.
    assert_eq!(
        planner.push(&StepMove {
            steps: [0, 0],
            ..good
        }),
        Ok(())
    );
    assert_eq!(
        Planner::<1>::new(f64::NAN).err(),
        Some(MotionError::InvalidJunctionDeviation)
    );
    assert_eq!(
        Planner::<1>::new(-1.0).err(),
        Some(MotionError::InvalidJunctionDeviation)
    );
    assert_eq!(
        SegmentPrep::new(0, 0.001).err(),
        Some(MotionError::InvalidTiming)
    );
    assert_eq!(
        SegmentPrep::new(1_000_000, f64::NAN).err(),
        Some(MotionError::InvalidTiming)
    );
    assert_eq!(
        SegmentPrep::new(1_000_000, 1.0).err(),
        Some(MotionError::InvalidTiming)
    );
}

/// A halt drops the current segment at once; nothing more steps until the
/// next prepared segment.
#[test]
fn halt_stops_steps_at_once() {
    let mut planner: Planner<2> = Planner::new(1.0).unwrap();
    let mut prep = SegmentPrep::new(TIMER_HZ, SEGMENT_S).unwrap();
    let mut queue: SegmentQueue<1> = SegmentQueue::default();
    let mut generator = StepGenerator::new();
    // 10 000 steps/s: 15 events per 1.5 ms segment.
    let mv = StepMove {
        steps: [5000, 0],
        nominal_rate_steps_per_s: 10_000.0,
        accel_steps_per_s2: 1.0e5,
    };
    planner.push(&mv).unwrap();
    let mut ticks = 0;
    while ticks < 50 || !generator.is_running() {
        prep.fill(&mut planner, &mut queue);
        generator.tick(&mut queue).unwrap();
        ticks += 1;
    }
    let at_halt = generator.position_steps();
    assert!(at_halt[0] > 0 && at_halt[0] < 5000);
    generator.halt();
    assert!(!generator.is_running());
    assert_eq!(generator.tick(&mut SegmentQueue::<1>::default()), None);
    assert_eq!(generator.position_steps(), at_halt);
}

/// Regression (a proptest case that failed on a clean run): a block of a
/// single step event after a long one at the lowest rate and acceleration.
/// The Bresenham counter started at ⌊1/2⌋ = 0 and never passed the event
/// count, so the block's only step was lost.
#[test]
fn single_event_block_steps() {
    let slow = |steps| StepMove {
        steps,
        nominal_rate_steps_per_s: 1.0,
        accel_steps_per_s2: 1.0,
    };
    let moves = [slow([50, 0]), slow([0, 1])];
    let events = run(&moves, 0.0, 0);
    assert_eq!(events.len(), 51);
    let pan = events.iter().filter(|e| e.tick.step[0]).count();
    let tilt = events.iter().filter(|e| e.tick.step[1]).count();
    assert_eq!((pan, tilt), (50, 1));
    assert_eq!(events[50].tick.step, [false, true]);
    // Any one-event block, alone, on either axis and direction.
    for steps in [[1, 0], [0, -1], [-1, 1]] {
        let events = run(&[slow(steps)], 0.0, 0);
        assert_eq!(events.len(), 1);
        let want = [steps[0] != 0, steps[1] != 0];
        assert_eq!(events[0].tick.step, want, "{steps:?}");
    }
}

/// Regression: an acceleration whose last-event period from rest,
/// √(2/a) = 6125.00006 µs, sits just above a whole tick. The decel rate
/// was peak² − 2·a·(s − s_dec), whose cancellation near rest put the
/// period at 6124.99… µs, rounded up to 6125: a last step faster than the
/// acceleration allows. Measured back from the end it rounds up to 6126.
#[test]
fn last_event_period_rounds_up_at_a_whole_tick() {
    let mv = |steps, rate, accel| StepMove {
        steps,
        nominal_rate_steps_per_s: rate,
        accel_steps_per_s2: accel,
    };
    let a = 53_311.119_320_422_71;
    let moves = [
        mv([0, 297], 1.0, 1.0),
        mv([77, 355], 1.0, 1.0),
        mv([987, 0], 15_261.526_868_328_068, a),
    ];
    let events = run(&moves, 13.562_702_382_435_747, 0);
    let last = events[events.len() - 1];
    assert_eq!(last.tick.period_ticks, 6126);
    assert!(last.rate <= libm::sqrt(a / 2.0));
}
