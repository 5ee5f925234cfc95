//! Planner queue of stepper blocks in grbl's shape (SPEC §4.4, seed:
//! grbl-pan-tilt-controller): each block is a straight move in integer
//! microsteps on the two axes (pan, tilt); its entry speed is limited by
//! grbl's junction-deviation rule and the whole queue is re-planned (a
//! reverse then a forward pass) as each block arrives, so the last block
//! always ends at rest.
//!
//! Speeds and accelerations are measured in **step events** along the
//! block: one event per step of the dominant axis (the axis with more
//! steps), so no axis ever steps faster than the block's rate. The
//! junction angle is taken between the moves' directions in step space.
//!
//! The queue, the reverse/forward passes and the junction rule are the
//! unit-agnostic [`crate::lookahead::Lookahead`] (the gimbal's G-code and
//! the galvo's marked paths plan through it in mm); this planner is its
//! step-space face: each block carries its microsteps and programmed feed
//! as the plan's data. Planning uses `f64`; it runs in a low-priority
//! task, never in the step path.

pub use super::motion::StepMove;

use super::motion::{MotionError, validate_move};
use crate::lookahead::{Lookahead, LookaheadBlock, LookaheadError, Move};

/// A block of the queue: a validated move and its planned speeds.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlannedBlock {
    /// Signed microsteps to move, `[pan, tilt]`.
    pub steps: [i32; 2],
    /// Step events of the block: the larger of `|steps|` (≥ 1).
    pub event_count: u32,
    /// Cruise rate, steps/s.
    pub nominal_rate_steps_per_s: f64,
    /// Acceleration limit, steps/s².
    pub accel_steps_per_s2: f64,
    /// Highest entry rate the junction with the previous block allows,
    /// steps/s (0 for the first block after rest).
    pub max_entry_rate_steps_per_s: f64,
    /// Planned entry rate, steps/s.
    pub entry_rate_steps_per_s: f64,
    /// Planned exit rate, steps/s (set when the block leaves the queue:
    /// the next block's entry rate, or 0 when it is the last).
    pub exit_rate_steps_per_s: f64,
    /// The programmed feed before the feed override, steps/s (0: a move
    /// at a fixed rate, which the override leaves alone).
    pub feed_rate_steps_per_s: f64,
}

/// What a stepper block carries beside its planned speeds.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct StepData {
    /// Signed microsteps to move, `[pan, tilt]`.
    pub steps: [i32; 2],
    /// The programmed feed before the feed override, steps/s (0: fixed).
    pub feed_rate_steps_per_s: f64,
}

/// Fixed-capacity look-ahead planner of up to `N` blocks in step space.
/// A capacity of 0 does not compile:
///
/// ```compile_fail
/// let _ = kinematics_core::stepper::Planner::<0>::new(1.0);
/// ```
#[derive(Debug, Clone)]
pub struct Planner<const N: usize> {
    plan: Lookahead<N, StepData>,
}

impl<const N: usize> Planner<N> {
    /// An empty planner. `junction_deviation_steps` (≥ 0, steps) is grbl's
    /// junction deviation δ expressed in microsteps.
    ///
    /// Errors: [`MotionError::InvalidJunctionDeviation`].
    pub fn new(junction_deviation_steps: f64) -> Result<Self, MotionError> {
        let plan = Lookahead::new(junction_deviation_steps)
            .map_err(|_| MotionError::InvalidJunctionDeviation)?;
        Ok(Self { plan })
    }

    /// Number of queued blocks.
    pub fn len(&self) -> usize {
        self.plan.len()
    }

    /// Whether no block is queued.
    pub fn is_empty(&self) -> bool {
        self.plan.is_empty()
    }

    /// The `i`-th queued block (0 = next to execute).
    pub fn block(&self, i: usize) -> Option<PlannedBlock> {
        self.plan.block(i).map(Self::planned)
    }

    fn planned(b: &LookaheadBlock<StepData>) -> PlannedBlock {
        PlannedBlock {
            steps: b.data.steps,
            feed_rate_steps_per_s: b.data.feed_rate_steps_per_s,
            // Lengths are whole step-event counts (≤ 2³⁰): exact.
            event_count: b.length as u32,
            nominal_rate_steps_per_s: b.nominal_speed,
            accel_steps_per_s2: b.accel,
            max_entry_rate_steps_per_s: b.max_entry_speed,
            entry_rate_steps_per_s: b.entry_speed,
            exit_rate_steps_per_s: b.exit_speed,
        }
    }

    /// Appends a move and re-plans the queue. A move of zero steps is
    /// accepted and ignored. On error nothing changes.
    ///
    /// Errors: [`MotionError::QueueFull`] and the move checks of
    /// [`validate_move`].
    pub fn push(&mut self, mv: &StepMove) -> Result<(), MotionError> {
        self.push_feed(mv, 0.0)
    }

    /// As [`Self::push`], for a move at a programmed feed: `feed_rate`
    /// (steps/s) is its rate before the feed override, kept for
    /// [`Self::rescale`] (0: a fixed rate).
    ///
    /// Errors: as [`Self::push`].
    pub fn push_feed(&mut self, mv: &StepMove, feed_rate: f64) -> Result<(), MotionError> {
        if validate_move(mv)? == 0 {
            return Ok(());
        }
        Self::push_plan(&mut self.plan, mv, feed_rate)
    }

    /// A new feed override: every queued block at a programmed feed
    /// cruises at `rate_of(feed)` from now on and the queue is re-planned;
    /// the head block's entry stays as it was (the block before it is
    /// already heading there).
    pub fn rescale(&mut self, rate_of: impl Fn(f64) -> f64) {
        let Some(entry) = self.plan.block(0).map(|b| b.entry_speed) else {
            return;
        };
        let old = self.plan.clone();
        self.plan.clear();
        for b in (0..old.len()).filter_map(|i| old.block(i)) {
            let feed = b.data.feed_rate_steps_per_s;
            let mv = StepMove {
                steps: b.data.steps,
                nominal_rate_steps_per_s: if feed > 0.0 {
                    rate_of(feed)
                } else {
                    b.nominal_speed
                },
                accel_steps_per_s2: b.accel,
            };
            // Re-pushing what was queued: only a refused rate can fail,
            // and then the block keeps its old one.
            if Self::push_plan(&mut self.plan, &mv, feed).is_err() {
                let mv = StepMove {
                    nominal_rate_steps_per_s: b.nominal_speed,
                    ..mv
                };
                let _ = Self::push_plan(&mut self.plan, &mv, feed);
            }
        }
        self.plan.limit_head_entry(entry);
    }

    /// Pushes a validated, non-empty move onto the plan.
    fn push_plan(
        plan: &mut Lookahead<N, StepData>,
        mv: &StepMove,
        feed_rate: f64,
    ) -> Result<(), MotionError> {
        let event_count = validate_move(mv)?;
        let norm = crate::numeric::hypot(f64::from(mv.steps[0]), f64::from(mv.steps[1]));
        let unit = [f64::from(mv.steps[0]) / norm, f64::from(mv.steps[1]) / norm];
        let data = StepData {
            steps: mv.steps,
            feed_rate_steps_per_s: feed_rate,
        };
        plan.push_move(
            Move::new(
                f64::from(event_count),
                [unit; 2],
                mv.nominal_rate_steps_per_s,
                mv.accel_steps_per_s2,
            ),
            data,
        )
        .map_err(|e| match e {
            LookaheadError::Full => MotionError::QueueFull,
            _ => MotionError::InvalidRate,
        })
    }

    /// Lowers the head block's entry rate to at most `rate` (steps/s: the
    /// block being executed now ends slower) and re-plans.
    pub fn limit_head_entry(&mut self, rate: f64) {
        self.plan.limit_head_entry(rate);
    }

    /// Drops every queued block (after a hold or a halt); the next block
    /// starts from rest.
    pub fn clear(&mut self) {
        self.plan.clear();
    }

    /// Takes the head block for execution, with its exit rate set. The
    /// next block's entry rate is then fixed: later blocks can only raise
    /// the speeds of the blocks before them, so that entry stays feasible.
    pub fn pop(&mut self) -> Option<PlannedBlock> {
        self.plan.pop().as_ref().map(Self::planned)
    }
}

/// grbl's junction-deviation limit between two unit directions in step
/// space ([`crate::lookahead::junction_speed`]): `accel_steps_per_s2` in
/// steps/s², `deviation_steps` in steps; returns steps/s.
pub fn junction_rate_steps_per_s(
    u_in: [f64; 2],
    u_out: [f64; 2],
    accel_steps_per_s2: f64,
    deviation_steps: f64,
) -> f64 {
    crate::lookahead::junction_speed(u_in, u_out, accel_steps_per_s2, deviation_steps)
}
