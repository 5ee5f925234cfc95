//! grbl's look-ahead planner, unit-agnostic (seed: grbl-pan-tilt-controller;
//! SPEC §8) — the one planner of the three actuators: a ring of blocks,
//! each with a length, a cruise speed and an acceleration limit in the
//! caller's units (mm, mm/s, mm/s² for G-code on the gimbal and the
//! galvo's marked paths; step events, steps/s, steps/s² for the stepper)
//! and the caller's own data beside it (`T`: the stepper's microsteps, the
//! galvo's geometry). A block's entry speed is limited by grbl's
//! junction-deviation rule ([`junction_speed`], `$11`) at the corner with
//! the block before, and the whole queue is re-planned (a reverse then a
//! forward pass) as each block arrives, so the last block always ends at
//! rest.
//!
//! [`SpeedCursor`] follows the planned profile at a fixed period (the
//! gimbal's streaming): the speed rises at the limit, cruises, and falls
//! so that every block's planned exit speed is met; a feed hold brakes at
//! the limit wherever it is.
//!
//! The capacity `N` must be at least 1 (checked at compile time):
//!
//! ```compile_fail
//! let _ = kinematics_core::lookahead::Lookahead::<0>::new(0.01);
//! ```

use crate::ring::Ring;

mod block;
mod cursor;

pub use block::LookaheadBlock;
pub use cursor::SpeedCursor;

/// Why a block was refused. Nothing changes on error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LookaheadError {
    /// Length, speed or acceleration not finite or ≤ 0, or a direction
    /// that is not a unit vector.
    InvalidBlock,
    /// Junction deviation not finite or negative.
    InvalidConfig,
    /// The queue is full; try again once a block has left.
    Full,
}

/// A move offered to the planner (caller's units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// Length (> 0).
    pub length: f64,
    /// Unit direction where the move starts.
    pub unit_in: [f64; 2],
    /// Unit direction where it ends (`unit_in` for a straight move; an
    /// arc's end tangent).
    pub unit_out: [f64; 2],
    /// Cruise speed (> 0), length/s.
    pub nominal_speed: f64,
    /// Acceleration limit along the move (> 0), length/s².
    pub accel: f64,
    /// Acceleration the junction rule takes at the move's corners (> 0;
    /// the lower of the two moves' at a corner), length/s²: `accel`,
    /// unless the move's limit along it is lowered for another reason
    /// (the galvo's arcs keep room for the centripetal part).
    pub junction_accel: f64,
}

impl Move {
    /// A move of `length` from direction `unit_in` to `unit_out` whose
    /// corners are taken at its own acceleration.
    pub fn new(
        length: f64,
        [unit_in, unit_out]: [[f64; 2]; 2],
        nominal_speed: f64,
        accel: f64,
    ) -> Self {
        Self {
            length,
            unit_in,
            unit_out,
            nominal_speed,
            accel,
            junction_accel: accel,
        }
    }

    fn is_valid(&self) -> bool {
        // Finite and > 0: the bits of +min-subnormal..=+MAX (integer
        // compares; soft-float ones cost ~20 M4 instructions each).
        let positive = |v: f64| v.to_bits().wrapping_sub(1) < f64::MAX.to_bits();
        // |u|² within 2e-6 of 1 (|u| within 1e-6): no square root, and
        // in `f32` on the FPU (NaN fails the compare).
        let is_unit = |u: [f64; 2]| {
            let (x, y) = (u[0] as f32, u[1] as f32);
            libm::fabsf(x * x + y * y - 1.0) < 2e-6
        };
        let same = |a: [f64; 2], b: [f64; 2]| a.map(f64::to_bits) == b.map(f64::to_bits);
        positive(self.length)
            && positive(self.nominal_speed)
            && positive(self.accel)
            && positive(self.junction_accel)
            && is_unit(self.unit_in)
            && (same(self.unit_in, self.unit_out) || is_unit(self.unit_out))
    }
}

/// Fixed-capacity look-ahead planner of up to `N` blocks, each carrying
/// the caller's `T`.
#[derive(Debug, Clone)]
pub struct Lookahead<const N: usize, T: Copy = ()> {
    blocks: Ring<LookaheadBlock<T>, N>,
    junction_deviation: f64,
    /// Unit direction and junction acceleration of the last queued block
    /// (`None`: the next block starts from rest).
    last: Option<([f64; 2], f64)>,
    /// Entry speed of the head block once its predecessor left the queue
    /// (execution is already heading towards it).
    frozen_head_entry: Option<f64>,
}

impl<const N: usize, T: Copy> Lookahead<N, T> {
    /// An empty planner; `junction_deviation` (≥ 0) is grbl's δ in the
    /// caller's length unit.
    ///
    /// Errors: [`LookaheadError::InvalidConfig`].
    pub fn new(junction_deviation: f64) -> Result<Self, LookaheadError> {
        if !(junction_deviation.is_finite() && junction_deviation >= 0.0) {
            return Err(LookaheadError::InvalidConfig);
        }
        Ok(Self {
            blocks: Ring::new(),
            junction_deviation,
            last: None,
            frozen_head_entry: None,
        })
    }

    /// Number of queued blocks.
    pub fn len(&self) -> usize {
        self.blocks.len()
    }

    /// Whether no block is queued.
    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    /// Whether no block can be queued.
    pub fn is_full(&self) -> bool {
        self.blocks.is_full()
    }

    /// The `i`-th queued block (0 = next to execute).
    pub fn block(&self, i: usize) -> Option<&LookaheadBlock<T>> {
        self.blocks.get(i)
    }

    /// Appends `mv` with the caller's `data` and re-plans the queue.
    ///
    /// Errors: [`LookaheadError::InvalidBlock`], [`LookaheadError::Full`].
    pub fn push_move(&mut self, mv: Move, data: T) -> Result<(), LookaheadError> {
        if !mv.is_valid() {
            return Err(LookaheadError::InvalidBlock);
        }
        if self.blocks.is_full() {
            return Err(LookaheadError::Full);
        }
        let max_entry = match (self.blocks.back(), self.last) {
            (Some(prev), Some((unit, junction_accel))) => junction_speed(
                unit,
                mv.unit_in,
                junction_accel.min(mv.junction_accel),
                self.junction_deviation,
            )
            .min(prev.nominal_speed)
            .min(mv.nominal_speed),
            _ => 0.0,
        };
        let block = LookaheadBlock {
            length: mv.length,
            nominal_speed: mv.nominal_speed,
            accel: mv.accel,
            max_entry_speed: max_entry,
            entry_speed: 0.0,
            exit_speed: 0.0,
            data,
        };
        if self.blocks.push_back(block).is_err() {
            return Err(LookaheadError::Full);
        }
        self.last = Some((mv.unit_out, mv.junction_accel));
        self.replan();
        Ok(())
    }

    /// Appends a stop: a block of no length that the motion before it
    /// reaches at rest and the motion after it leaves from rest (the
    /// galvo's jump between two marked paths). Its data tells the caller
    /// what the stop is.
    ///
    /// Errors: [`LookaheadError::Full`].
    pub fn push_stop(&mut self, data: T) -> Result<(), LookaheadError> {
        let stop = LookaheadBlock {
            length: 0.0,
            nominal_speed: 0.0,
            accel: 0.0,
            max_entry_speed: 0.0,
            entry_speed: 0.0,
            exit_speed: 0.0,
            data,
        };
        if self.blocks.push_back(stop).is_err() {
            return Err(LookaheadError::Full);
        }
        // No re-plan: the queue before it already ended at rest, and a
        // stop at rest changes none of its speeds.
        self.last = None;
        Ok(())
    }

    /// The next block pushed starts from rest (a dwell or a pause between
    /// the blocks): the queue so far plans to end at rest.
    pub fn break_junction(&mut self) {
        self.last = None;
    }

    /// Drops every queued block (after a hold or a halt); the next block
    /// starts from rest.
    pub fn clear(&mut self) {
        self.blocks.clear();
        self.frozen_head_entry = None;
        self.last = None;
    }

    /// Takes the head block for execution, with its exit speed set. The
    /// next block's entry speed is then fixed: later blocks can only raise
    /// the speeds of the blocks before them, so that entry stays feasible.
    pub fn pop(&mut self) -> Option<LookaheadBlock<T>> {
        let mut block = self.blocks.pop_front()?;
        let next = self.blocks.front().map(|b| b.entry_speed);
        block.exit_speed = next.unwrap_or(0.0);
        self.frozen_head_entry = next;
        if next.is_none() {
            // The executor now plans the popped block to rest; what comes
            // next starts from rest.
            self.last = None;
        }
        Some(block)
    }

    /// Lowers the head block's entry speed to at most `speed` (the block
    /// before it stopped short of its planned exit: a feed hold) and
    /// re-plans.
    pub fn limit_head_entry(&mut self, speed: f64) {
        let speed = speed.max(0.0);
        if !self.blocks.is_empty() {
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
        let len = self.blocks.len();
        // Whether the frozen head cannot brake to the entry the reverse
        // pass wants for the block after it (see the forward pass).
        let mut brake_through = false;
        for i in (0..len).rev() {
            let Some(b) = self.blocks.get_mut(i) else {
                continue;
            };
            b.entry_speed = match (i, frozen) {
                (0, Some(frozen)) => {
                    brake_through = i + 1 < len
                        && at_least_braking(next_entry, frozen, b.accel, b.length) > next_entry;
                    frozen
                }
                // From rest (a stop, a break, the first block): no `√`
                // (soft-float on the M4) for min(0, reach) = 0.
                _ if is_rest(b.max_entry_speed) => b.max_entry_speed,
                _ => b
                    .max_entry_speed
                    .min(reachable_speed(next_entry, b.accel, b.length)),
            };
            next_entry = b.entry_speed;
        }
        // The forward pass, with the block before's entry, acceleration
        // and length carried along: every entry reachable from the one
        // before. After a frozen head entry above what the reverse pass
        // wanted (a feed override lowered the cruise of blocks the spot is
        // already heading into faster), also at least what braking at the
        // limit leaves: those blocks brake above their new cruise instead
        // of jumping down to it, until the plan is met again. (Checked
        // only then: soft-float squares cost ~800 M4 instructions a block.)
        let Some(head) = self.blocks.get(0) else {
            return;
        };
        let (mut entry, mut accel, mut length) = (head.entry_speed, head.accel, head.length);
        for i in 1..len {
            let Some(b) = self.blocks.get_mut(i) else {
                continue;
            };
            // An entry at rest stays at rest: no `√` for it.
            if !is_rest(b.entry_speed) {
                let reached = b.entry_speed.min(reachable_speed(entry, accel, length));
                b.entry_speed = reached;
                if brake_through {
                    b.entry_speed = at_least_braking(reached, entry, accel, length);
                    brake_through = b.entry_speed > reached;
                }
            }
            (entry, accel, length) = (b.entry_speed, b.accel, b.length);
        }
    }
}

/// Whether a speed (never negative) is 0: a bit test, not a soft-float
/// compare (~20 M4 instructions).
#[inline(always)]
fn is_rest(speed: f64) -> bool {
    speed.to_bits() << 1 == 0
}

impl<const N: usize> Lookahead<N> {
    /// Appends a block of `length` that starts along the unit direction
    /// `unit_in` and ends along `unit_out` (the same for a straight block;
    /// an arc's tangents) and re-plans the queue ([`Self::push_move`]
    /// without data).
    ///
    /// Errors: [`LookaheadError::InvalidBlock`], [`LookaheadError::Full`].
    pub fn push(
        &mut self,
        length: f64,
        units: [[f64; 2]; 2],
        nominal_speed: f64,
        accel: f64,
    ) -> Result<(), LookaheadError> {
        self.push_move(Move::new(length, units, nominal_speed, accel), ())
    }
}

/// Speed reachable from `speed` over `length` at `accel`: √(v² + 2·a·d).
pub fn reachable_speed(speed: f64, accel: f64, length: f64) -> f64 {
    libm::sqrt(speed * speed + 2.0 * accel * length)
}

/// `speed`, raised to the lowest speed a move entered at `from` can leave
/// with when braking at `accel` over `length` (units as
/// [`reachable_speed`]). The square of that floor is taken 1e-12
/// (relative) low, so a plan that stops exactly within the move
/// (v² = 2·a·d up to rounding) is left alone; the `√` runs only when the
/// floor binds.
fn at_least_braking(speed: f64, from: f64, accel: f64, length: f64) -> f64 {
    let (v2, d2) = (from * from, 2.0 * accel * length);
    let floor2 = v2 - d2 - 1e-12 * (v2 + d2);
    if speed * speed < floor2 {
        libm::sqrt(floor2)
    } else {
        speed
    }
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

#[cfg(test)]
mod tests;
