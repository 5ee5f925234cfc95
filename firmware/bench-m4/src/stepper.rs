//! The stepper's step path (issue 13): the step generator's work per step
//! event (Bresenham on two axes, integers only) and per segment (loading
//! the next prepared segment), as the step timer runs it inside its
//! critical section (the lock itself, `cpsid`/`cpsie` around it on the
//! target, is a few instructions more); the same per event with the
//! one-pulse timer's values chosen as the STM32 board's step does (DIR
//! change, [`OnePulseTiming::event`]; the board's five timer register
//! stores are not in it: QEMU's board has no TIM1). Segment prep (f64, low
//! priority) is reported for scale.

use core::hint::black_box;

use kinematics_core::stepper::{
    Planner, Segment, SegmentPrep, SegmentQueue, StepBlock, StepGenerator, StepMove,
};

use laser_app::stepper::{DriverSignals, OnePulseTiming};

use crate::harness::{Bench, window};

/// Segments the step timer has ahead of it (as in laser-app).
const QUEUE: usize = 8;
/// Step events per segment in the per-event window: 1.5 ms at 50 kHz.
const EVENTS_PER_SEGMENT: u32 = 75;

/// A diagonal block stepping both axes on most events.
const BLOCK: StepBlock = StepBlock {
    steps: [60_000, 45_000],
    negative: [false, true],
    event_count: 60_000,
};

fn segment(events: u32, starts_block: bool) -> Segment {
    Segment {
        block: BLOCK,
        starts_block,
        events,
        period_ticks: 20,
        speed_permille: 1000,
    }
}

/// A full queue of `QUEUE` segments of `events` events each, the first
/// starting the block, and a generator at rest.
fn loaded(events: u32) -> (SegmentQueue<QUEUE>, StepGenerator) {
    let mut queue = SegmentQueue::new();
    for k in 0..QUEUE {
        let _ = queue.push_back(segment(events, k == 0));
    }
    (queue, StepGenerator::new())
}

/// Per step event and per segment, and the prep for scale.
pub fn stepper(b: &mut Bench) {
    per_event(b);
    per_event_one_pulse(b);
    per_segment(b);
    prep(b);
}

/// `QUEUE` segments of 75 events: one segment load per 75 events, as at
/// 50 kHz with 1.5 ms segments.
#[inline(always)]
fn per_event(b: &mut Bench) {
    let (mut queue, mut generator) = loaded(EVENTS_PER_SEGMENT);
    let events = EVENTS_PER_SEGMENT * QUEUE as u32;
    let ticks = window(|| {
        for _ in 0..events {
            black_box(generator.tick(black_box(&mut queue)));
        }
    });
    b.report("stepper.step_tick.event", ticks, events);
}

/// As [`per_event`], plus what the STM32 board's step computes for its
/// one-pulse timer: whether a DIR pin changed, and the event's compare,
/// reload and channel modes (TIM1 at 168 MHz, the default 2.5 µs pulse
/// and 5 µs DIR setup).
#[inline(always)]
fn per_event_one_pulse(b: &mut Bench) {
    let (mut queue, mut generator) = loaded(EVENTS_PER_SEGMENT);
    let signals = DriverSignals {
        pulse_ns: 2_500,
        dir_setup_ns: 5_000,
        enable_active_high: false,
    };
    let timing = black_box(OnePulseTiming::new(168_000_000, signals));
    let mut dir = [false; 2];
    let events = EVENTS_PER_SEGMENT * QUEUE as u32;
    let ticks = window(|| {
        for _ in 0..events {
            if let Some(tick) = generator.tick(black_box(&mut queue)) {
                let dir_changed = tick.negative != dir;
                dir = tick.negative;
                black_box(timing.event(tick.step, dir_changed));
            }
        }
    });
    b.report("stepper.step_tick.event_one_pulse", ticks, events);
}

/// One-event segments: every event loads a segment (the worst case).
#[inline(always)]
fn per_segment(b: &mut Bench) {
    let (mut queue, mut generator) = loaded(1);
    let ticks = window(|| {
        for _ in 0..QUEUE {
            black_box(generator.tick(black_box(&mut queue)));
        }
    });
    b.report("stepper.step_tick.segment", ticks, QUEUE as u32);
}

/// Segment prep of a cruising block (f64 profile, low priority).
#[inline(always)]
fn prep(b: &mut Bench) {
    let Ok(mut planner) = Planner::<4>::new(1.0) else {
        return b.fail("stepper.prep", "planner");
    };
    let Ok(mut prep) = SegmentPrep::new(1_000_000, 0.0015) else {
        return b.fail("stepper.prep", "prep");
    };
    let mv = StepMove {
        steps: [60_000, 45_000],
        nominal_rate_steps_per_s: 50_000.0,
        accel_steps_per_s2: 500_000.0,
    };
    if planner.push(&mv).is_err() {
        return b.fail("stepper.prep", "push");
    }
    const N: u32 = 64;
    let ticks = window(|| {
        for _ in 0..N {
            black_box(prep.next_segment(black_box(&mut planner)));
        }
    });
    b.report("stepper.prep.segment", ticks, N);
}
