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
//! Planning uses `f64`; it runs in a low-priority task, never in the step
//! path.

use super::motion::{MotionError, validate_move};

/// One requested move: signed microsteps per axis (pan, tilt) and its
/// limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepMove {
    /// Signed microsteps to move, `[pan, tilt]`.
    pub steps: [i32; 2],
    /// Cruise rate, step events per second (dominant axis, steps/s).
    pub nominal_rate_steps_per_s: f64,
    /// Acceleration limit, step events per second² (steps/s²).
    pub accel_steps_per_s2: f64,
}

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
}

/// Fixed-capacity look-ahead planner of up to `N` blocks.
#[derive(Debug, Clone)]
pub struct Planner<const N: usize> {
    blocks: [PlannedBlock; N],
    head: usize,
    len: usize,
    junction_deviation_steps: f64,
    /// Unit direction (step space) of the last queued block.
    last_unit: [f64; 2],
    /// Entry rate of the head block once its predecessor left the queue
    /// (the segment prep is already executing towards it), steps/s.
    frozen_head_entry: Option<f64>,
}

impl<const N: usize> Planner<N> {
    /// An empty planner. `junction_deviation_steps` (≥ 0, steps) is grbl's
    /// junction deviation δ expressed in microsteps.
    ///
    /// Errors: [`MotionError::InvalidJunctionDeviation`],
    /// [`MotionError::ZeroCapacity`].
    pub fn new(junction_deviation_steps: f64) -> Result<Self, MotionError> {
        if N == 0 {
            return Err(MotionError::ZeroCapacity);
        }
        if !(junction_deviation_steps.is_finite() && junction_deviation_steps >= 0.0) {
            return Err(MotionError::InvalidJunctionDeviation);
        }
        Ok(Self {
            blocks: [PlannedBlock::default(); N],
            head: 0,
            len: 0,
            junction_deviation_steps,
            last_unit: [0.0; 2],
            frozen_head_entry: None,
        })
    }

    /// Number of queued blocks.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no block is queued.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The `i`-th queued block (0 = next to execute).
    pub fn block(&self, i: usize) -> Option<&PlannedBlock> {
        if i < self.len {
            self.blocks.get((self.head + i) % N)
        } else {
            None
        }
    }

    /// The `i`-th queued block, mutable.
    fn block_mut(&mut self, i: usize) -> Option<&mut PlannedBlock> {
        if i < self.len {
            self.blocks.get_mut((self.head + i) % N)
        } else {
            None
        }
    }

    /// Appends a move and re-plans the queue. A move of zero steps is
    /// accepted and ignored. On error nothing changes.
    ///
    /// Errors: [`MotionError::QueueFull`] and the move checks of
    /// [`validate_move`].
    pub fn push(&mut self, mv: &StepMove) -> Result<(), MotionError> {
        let event_count = validate_move(mv)?;
        if event_count == 0 {
            return Ok(());
        }
        if self.len == N {
            return Err(MotionError::QueueFull);
        }
        let norm = libm::hypot(f64::from(mv.steps[0]), f64::from(mv.steps[1]));
        let unit = [f64::from(mv.steps[0]) / norm, f64::from(mv.steps[1]) / norm];
        let max_entry = match self.len.checked_sub(1).and_then(|i| self.block(i)) {
            None => 0.0,
            Some(prev) => junction_rate_steps_per_s(
                self.last_unit,
                unit,
                prev.accel_steps_per_s2.min(mv.accel_steps_per_s2),
                self.junction_deviation_steps,
            )
            .min(prev.nominal_rate_steps_per_s)
            .min(mv.nominal_rate_steps_per_s),
        };
        let Some(slot) = self.blocks.get_mut((self.head + self.len) % N) else {
            return Err(MotionError::QueueFull);
        };
        *slot = PlannedBlock {
            steps: mv.steps,
            event_count,
            nominal_rate_steps_per_s: mv.nominal_rate_steps_per_s,
            accel_steps_per_s2: mv.accel_steps_per_s2,
            max_entry_rate_steps_per_s: max_entry,
            entry_rate_steps_per_s: 0.0,
            exit_rate_steps_per_s: 0.0,
        };
        self.len += 1;
        self.last_unit = unit;
        self.replan();
        Ok(())
    }

    /// Drops every queued block (after a hold or a halt); the next block
    /// starts from rest.
    pub fn clear(&mut self) {
        self.len = 0;
        self.frozen_head_entry = None;
    }

    /// Takes the head block for execution, with its exit rate set. The
    /// next block's entry rate is then fixed: later blocks can only raise
    /// the speeds of the blocks before them, so that entry stays feasible.
    pub fn pop(&mut self) -> Option<PlannedBlock> {
        let mut block = *self.block(0)?;
        self.head = (self.head + 1) % N;
        self.len -= 1;
        block.exit_rate_steps_per_s = self.block(0).map_or(0.0, |b| b.entry_rate_steps_per_s);
        self.frozen_head_entry = (self.len > 0).then_some(block.exit_rate_steps_per_s);
        Some(block)
    }

    /// Reverse pass (every block can still stop by the end of the queue),
    /// then forward pass (every entry is reachable from the one before).
    fn replan(&mut self) {
        let mut next_entry = 0.0_f64;
        let frozen = self.frozen_head_entry;
        for i in (0..self.len).rev() {
            let Some(b) = self.block_mut(i) else { continue };
            let reach = reachable(next_entry, b.accel_steps_per_s2, b.event_count);
            b.entry_rate_steps_per_s = match (i, frozen) {
                (0, Some(frozen)) => frozen,
                _ => b.max_entry_rate_steps_per_s.min(reach),
            };
            next_entry = b.entry_rate_steps_per_s;
        }
        for i in 0..self.len.saturating_sub(1) {
            let Some(&b) = self.block(i) else { continue };
            let reach = reachable(
                b.entry_rate_steps_per_s,
                b.accel_steps_per_s2,
                b.event_count,
            );
            if let Some(next) = self.block_mut(i + 1) {
                next.entry_rate_steps_per_s = next.entry_rate_steps_per_s.min(reach);
            }
        }
    }
}

/// Rate reachable from `rate` (steps/s) over `events` steps at `accel`
/// (steps/s²): √(v² + 2·a·d), steps/s.
pub(crate) fn reachable(rate: f64, accel: f64, events: u32) -> f64 {
    libm::sqrt(rate * rate + 2.0 * accel * f64::from(events))
}

/// grbl's junction-deviation limit between two unit directions: with θ
/// the angle between the moves' directions and `cos θ = −u_in·u_out`,
/// v² = a·δ·sin(θ/2) / (1 − sin(θ/2)). A reversal gives 0, a straight
/// continuation `f64::INFINITY` (only the nominal rates limit it).
///
/// `accel_steps_per_s2` in steps/s², `deviation_steps` in steps; returns
/// steps/s.
pub fn junction_rate_steps_per_s(
    u_in: [f64; 2],
    u_out: [f64; 2],
    accel_steps_per_s2: f64,
    deviation_steps: f64,
) -> f64 {
    let cos_theta = -(u_in[0] * u_out[0] + u_in[1] * u_out[1]);
    if cos_theta > 0.999_999 {
        return 0.0;
    }
    if cos_theta < -0.999_999 {
        return f64::INFINITY;
    }
    let sin_half = libm::sqrt(0.5 * (1.0 - cos_theta));
    libm::sqrt(accel_steps_per_s2 * deviation_steps * sin_half / (1.0 - sin_half))
}
