//! grbl's look-ahead planner, unit-agnostic (seed: grbl-pan-tilt-controller;
//! SPEC §8): a ring of straight blocks, each with a length, a cruise speed
//! and an acceleration limit in the caller's units (mm, mm/s, mm/s² for
//! G-code on the gimbal; step events, steps/s, steps/s² for the stepper).
//! A block's entry speed is limited by grbl's junction-deviation rule at
//! the corner with the block before, and the whole queue is re-planned (a
//! reverse then a forward pass) as each block arrives, so the last block
//! always ends at rest.
//!
//! [`SpeedCursor`] follows the planned profile at a fixed period (the
//! gimbal's streaming): the speed rises at the limit, cruises, and falls
//! so that every block's planned exit speed is met; a feed hold brakes at
//! the limit wherever it is.

/// Why a block was refused. Nothing changes on error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LookaheadError {
    /// Length, speed or acceleration not finite or ≤ 0, or a direction
    /// that is not a unit vector.
    InvalidBlock,
    /// Junction deviation not finite or negative, or capacity 0.
    InvalidConfig,
    /// The queue is full; try again once a block has left.
    Full,
}

/// A block of the queue with its planned speeds (caller's units).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LookaheadBlock {
    /// Length (> 0).
    pub length: f64,
    /// Cruise speed (> 0), length/s.
    pub nominal_speed: f64,
    /// Acceleration limit (> 0), length/s².
    pub accel: f64,
    /// Highest entry speed the junction with the previous block allows
    /// (0 for the first block after rest), length/s.
    pub max_entry_speed: f64,
    /// Planned entry speed, length/s.
    pub entry_speed: f64,
    /// Planned exit speed (set when the block leaves the queue: the next
    /// block's entry speed, or 0 when it is the last), length/s.
    pub exit_speed: f64,
}

/// Fixed-capacity look-ahead planner of up to `N` blocks.
#[derive(Debug, Clone)]
pub struct Lookahead<const N: usize> {
    blocks: [LookaheadBlock; N],
    head: usize,
    len: usize,
    junction_deviation: f64,
    /// Unit direction of the last queued block (`None`: the next block
    /// starts from rest).
    last_unit: Option<[f64; 2]>,
    /// Entry speed of the head block once its predecessor left the queue
    /// (execution is already heading towards it).
    frozen_head_entry: Option<f64>,
}

impl<const N: usize> Lookahead<N> {
    /// An empty planner; `junction_deviation` (≥ 0) is grbl's δ in the
    /// caller's length unit.
    ///
    /// Errors: [`LookaheadError::InvalidConfig`].
    pub fn new(junction_deviation: f64) -> Result<Self, LookaheadError> {
        if N == 0 || !(junction_deviation.is_finite() && junction_deviation >= 0.0) {
            return Err(LookaheadError::InvalidConfig);
        }
        Ok(Self {
            blocks: [LookaheadBlock::default(); N],
            head: 0,
            len: 0,
            junction_deviation,
            last_unit: None,
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

    /// Whether no block can be queued.
    pub fn is_full(&self) -> bool {
        self.len == N
    }

    /// The `i`-th queued block (0 = next to execute).
    pub fn block(&self, i: usize) -> Option<&LookaheadBlock> {
        if i < self.len {
            self.blocks.get((self.head + i) % N)
        } else {
            None
        }
    }

    fn block_mut(&mut self, i: usize) -> Option<&mut LookaheadBlock> {
        if i < self.len {
            self.blocks.get_mut((self.head + i) % N)
        } else {
            None
        }
    }

    /// Appends a block of `length` that starts along the unit direction
    /// `unit_in` and ends along `unit_out` (the same for a straight block;
    /// an arc's tangents) and re-plans the queue.
    ///
    /// Errors: [`LookaheadError::InvalidBlock`], [`LookaheadError::Full`].
    pub fn push(
        &mut self,
        length: f64,
        [unit_in, unit_out]: [[f64; 2]; 2],
        nominal_speed: f64,
        accel: f64,
    ) -> Result<(), LookaheadError> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        let is_unit = |u: [f64; 2]| libm::fabs(crate::numeric::hypot(u[0], u[1]) - 1.0) < 1e-6;
        let valid = positive(length) && positive(nominal_speed) && positive(accel);
        if !(valid && is_unit(unit_in) && is_unit(unit_out)) {
            return Err(LookaheadError::InvalidBlock);
        }
        if self.len == N {
            return Err(LookaheadError::Full);
        }
        let prev = self.len.checked_sub(1).and_then(|i| self.block(i)).copied();
        let max_entry = match (prev, self.last_unit) {
            (Some(prev), Some(last)) => junction_speed(
                last,
                unit_in,
                prev.accel.min(accel),
                self.junction_deviation,
            )
            .min(prev.nominal_speed)
            .min(nominal_speed),
            _ => 0.0,
        };
        let Some(slot) = self.blocks.get_mut((self.head + self.len) % N) else {
            return Err(LookaheadError::Full);
        };
        *slot = LookaheadBlock {
            length,
            nominal_speed,
            accel,
            max_entry_speed: max_entry,
            entry_speed: 0.0,
            exit_speed: 0.0,
        };
        self.len += 1;
        self.last_unit = Some(unit_out);
        self.replan();
        Ok(())
    }

    /// The next block pushed starts from rest (a dwell or a pause between
    /// the blocks): the queue so far plans to end at rest.
    pub fn break_junction(&mut self) {
        self.last_unit = None;
    }

    /// Drops every queued block (after a hold or a halt); the next block
    /// starts from rest.
    pub fn clear(&mut self) {
        self.len = 0;
        self.frozen_head_entry = None;
        self.last_unit = None;
    }

    /// Takes the head block for execution, with its exit speed set. The
    /// next block's entry speed is then fixed: later blocks can only raise
    /// the speeds of the blocks before them, so that entry stays feasible.
    pub fn pop(&mut self) -> Option<LookaheadBlock> {
        let mut block = *self.block(0)?;
        self.head = (self.head + 1) % N;
        self.len -= 1;
        block.exit_speed = self.block(0).map_or(0.0, |b| b.entry_speed);
        self.frozen_head_entry = (self.len > 0).then_some(block.exit_speed);
        if self.len == 0 {
            // The executor now plans the popped block to rest; what comes
            // next starts from rest.
            self.last_unit = None;
        }
        Some(block)
    }

    /// Lowers the head block's entry speed to at most `speed` (the block
    /// before it stopped short of its planned exit: a feed hold) and
    /// re-plans.
    pub fn limit_head_entry(&mut self, speed: f64) {
        let speed = speed.max(0.0);
        if self.len > 0 {
            let entry = self.frozen_head_entry.map_or(speed, |f| f.min(speed));
            self.frozen_head_entry = Some(entry);
            self.replan();
        }
    }

    /// Reverse pass (every block can still stop by the end of the queue),
    /// then forward pass (every entry is reachable from the one before).
    fn replan(&mut self) {
        let mut next_entry = 0.0_f64;
        let frozen = self.frozen_head_entry;
        for i in (0..self.len).rev() {
            let Some(b) = self.block_mut(i) else { continue };
            let reach = reachable_speed(next_entry, b.accel, b.length);
            b.entry_speed = match (i, frozen) {
                (0, Some(frozen)) => frozen,
                _ => b.max_entry_speed.min(reach),
            };
            next_entry = b.entry_speed;
        }
        // Forward: every entry reachable from the one before, at most
        // accelerating and at least braking at the limit. The second bound
        // only binds after a frozen head entry above what the reverse pass
        // wanted (a feed override lowered the cruise of a block that is
        // already faster): the blocks after it then brake at the limit,
        // above their new cruise, instead of jumping down to it.
        for i in 0..self.len.saturating_sub(1) {
            let Some(&b) = self.block(i) else { continue };
            let reach = reachable_speed(b.entry_speed, b.accel, b.length);
            let floor = braking_speed(b.entry_speed, b.accel, b.length);
            if let Some(next) = self.block_mut(i + 1) {
                next.entry_speed = next.entry_speed.min(reach).max(floor);
            }
        }
    }
}

/// Speed reachable from `speed` over `length` at `accel`: √(v² + 2·a·d).
pub fn reachable_speed(speed: f64, accel: f64, length: f64) -> f64 {
    libm::sqrt(speed * speed + 2.0 * accel * length)
}

/// Lowest speed a move entered at `speed` can leave with: braking at
/// `accel` over `length` (0 when it can stop within it). Units as
/// [`reachable_speed`]. The square is taken 1e-12 (relative) low, so a
/// plan that stops exactly within the move (v² = 2·a·d up to rounding)
/// gives 0, not the √ of a rounding error.
pub fn braking_speed(speed: f64, accel: f64, length: f64) -> f64 {
    let (v2, d2) = (speed * speed, 2.0 * accel * length);
    libm::sqrt((v2 - d2 - 1e-12 * (v2 + d2)).max(0.0))
}

/// grbl's junction-deviation limit between two unit directions: with θ
/// the angle between the moves' directions and `cos θ = −u_in·u_out`,
/// v² = a·δ·sin(θ/2) / (1 − sin(θ/2)). A reversal gives 0, a straight
/// continuation `f64::INFINITY` (only the nominal speeds limit it).
///
/// `accel` in length/s², `deviation` in length; returns length/s.
pub fn junction_speed(u_in: [f64; 2], u_out: [f64; 2], accel: f64, deviation: f64) -> f64 {
    let cos_theta = -(u_in[0] * u_out[0] + u_in[1] * u_out[1]);
    if cos_theta > 0.999_999 {
        return 0.0;
    }
    if cos_theta < -0.999_999 {
        return f64::INFINITY;
    }
    let sin_half = libm::sqrt(0.5 * (1.0 - cos_theta));
    libm::sqrt(accel * deviation * sin_half / (1.0 - sin_half))
}

/// Follows a popped block's planned profile at a fixed period: where the
/// motion is along the block and how fast it goes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SpeedCursor {
    /// The block followed.
    pub block: LookaheadBlock,
    /// Distance done along it.
    pub done: f64,
    /// Speed now, length/s.
    pub speed: f64,
}

impl SpeedCursor {
    /// At the start of `block`, at its planned entry speed.
    pub fn start(block: LookaheadBlock) -> Self {
        Self {
            block,
            done: 0.0,
            speed: block.entry_speed,
        }
    }

    /// Advances by `dt_s` seconds with the cruise speed scaled by `scale`
    /// (feed override, > 0) — or braking at the limit when `hold` — and
    /// returns the distance by which the step ran past the block's end
    /// (`None` while inside it). The speed never rises or falls faster
    /// than the block's acceleration; it brakes on the discrete braking
    /// curve to the block's planned exit speed.
    pub fn advance(&mut self, dt_s: f64, scale: f64, hold: bool) -> Option<f64> {
        let b = self.block;
        let left = (b.length - self.done).max(0.0);
        let next = if hold {
            (self.speed - b.accel * dt_s).max(0.0)
        } else {
            let cruise = b.nominal_speed * scale.max(0.0);
            let up = (self.speed + b.accel * dt_s).min(cruise);
            let down = (self.speed - b.accel * dt_s).max(0.0);
            let mut brake = self.braking_speed(dt_s, left);
            if 0.5 * (self.speed + b.exit_speed) * dt_s >= left {
                // The end is reached within this period anyway: at most
                // at the exit speed.
                brake = brake.max(b.exit_speed);
            }
            up.min(brake).max(down)
        };
        let step = 0.5 * (self.speed + next) * dt_s;
        self.speed = next;
        if step >= left {
            self.done = b.length;
            return Some(step - left);
        }
        self.done += step;
        None
    }

    /// The highest speed at the end of a period of `dt_s` from which the
    /// block can still end at its exit speed with `left` to go (the
    /// discrete braking curve: v'² + a·dt·v' ≤ e² + 2·a·left − a·dt·v).
    fn braking_speed(&self, dt_s: f64, left: f64) -> f64 {
        let (a, e) = (self.block.accel, self.block.exit_speed);
        let adt = a * dt_s;
        let rhs = e * e + 2.0 * a * left - adt * self.speed;
        if rhs <= 0.0 {
            return 0.0;
        }
        0.5 * (libm::sqrt(adt * adt + 4.0 * rhs) - adt)
    }

    /// Continues into `block` (the next one popped) at the speed reached,
    /// `overshoot` into it.
    pub fn continue_into(&mut self, block: LookaheadBlock, overshoot: f64) {
        *self = Self {
            block,
            done: crate::numeric::clamp(overshoot, 0.0, block.length),
            speed: self.speed,
        };
    }

    /// Whether a hold has come to rest here.
    pub fn is_at_rest(&self) -> bool {
        self.speed <= 0.0
    }

    /// Fraction (0..=1) of the block done.
    pub fn fraction(&self) -> f64 {
        if self.block.length > 0.0 {
            crate::numeric::clamp(self.done / self.block.length, 0.0, 1.0)
        } else {
            1.0
        }
    }
}

#[cfg(test)]
mod tests;
