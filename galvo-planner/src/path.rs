//! Path marking with look-ahead (GRBL style) in the board plane.
//!
//! Segments (lines and circular arcs, mm) are added to a fixed-capacity
//! look-ahead planner (`CAP` blocks, one per segment, the running one
//! included: kinematics-core's [`Lookahead`], the planner the gimbal and
//! the stepper plan with too, each block carrying its geometry; 16 or more give a
//! streamed path GRBL's look-ahead; a caller that loads a whole stroke
//! before sampling it needs only the stroke's segments). Each block gets a speed cap (the
//! marking speed; on arcs also `√(a·r/√2)` so the centripetal acceleration
//! stays ≤ `a/√2`) and a tangential acceleration limit (`a` on lines,
//! `a/√2` on arcs, so the total acceleration on an arc is ≤ `a`). The speed
//! at each junction is limited by GRBL's junction-deviation rule
//! `v² = a·δ·sin(θ/2)/(1 − sin(θ/2))` (θ = angle between the reversed
//! incoming and the outgoing direction) and by both blocks' caps. Every time
//! a block is added the entry speeds are recomputed by a backward pass
//! (every block can still stop at the end of the buffer) and a forward pass
//! (reachable from the previous entry speed), over the blocks not yet being
//! executed.
//!
//! Sampling: when the sampler enters a block its trapezoidal speed profile
//! is frozen (so the running block never changes under it; later blocks
//! only raise the speeds reachable behind it) and evaluated at the sample
//! instants in `f32` — a few flops per sample on lines; on arcs the spot's
//! direction from the centre turns by the sample's arc length over the
//! radius as an incremental rotation ([`ArcRotor`]: a short polynomial and
//! a renormalisation, no `sinf`/`cosf`, which compute in `f64` and cost
//! ~1 200 instructions each on the M4F). Samples are uniform in time
//! across block boundaries; a path ends with one sample exactly on its
//! end point at zero speed.
//!
//! Separate paths are joined by jumps ([`PathPlanner::move_to`]); the
//! sampler reports a jump as [`MarkSample::Jump`] and pauses, so the caller
//! can run the mirror jump (in angle space, with the laser off) with the
//! [`jump`](crate::jump) planner and [`XyIntegrator`](crate::integrator::XyIntegrator).
//! The planner works in board coordinates only; converting them to mirror
//! angles is the caller's job (galvo kinematics live in another crate).

mod block;
mod rotor;
mod sampler;
mod segments;

use crate::error::{Error, positive};
use block::{Exec, IDLE_EXEC, Shape};
pub use kinematics_core::lookahead::junction_speed;
use kinematics_core::lookahead::{Lookahead, LookaheadError};
use kinematics_core::numeric::finite;
pub use rotor::ArcRotor;

/// Limits and sample period of the path planner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarkLimits {
    /// Marking speed (and speed limit), mm/s.
    pub speed_mm_s: f64,
    /// Acceleration limit, mm/s².
    pub accel_mm_s2: f64,
    /// Junction deviation δ, mm (GRBL `$11`; 0.01 mm is GRBL's default).
    pub junction_deviation_mm: f64,
    /// Sample period, s.
    pub ts_s: f64,
}

impl MarkLimits {
    fn validate(&self) -> Result<(), Error> {
        positive(self.speed_mm_s, "speed_mm_s")?;
        positive(self.accel_mm_s2, "accel_mm_s2")?;
        let jd = finite(self.junction_deviation_mm, "junction_deviation_mm")?;
        if jd < 0.0 {
            return Err(Error::NotPositive {
                name: "junction_deviation_mm",
                value: jd,
            });
        }
        if !self.ts_s.is_finite() || self.ts_s <= 0.0 {
            return Err(Error::InvalidSamplePeriod { ts_s: self.ts_s });
        }
        Ok(())
    }
}

/// One output of the sampler.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MarkSample {
    /// Laser on: the spot position at this sample and the path speed.
    Mark {
        /// Board x, mm.
        x_mm: f32,
        /// Board y, mm.
        y_mm: f32,
        /// Speed along the path, mm/s.
        speed_mm_s: f32,
    },
    /// The next path starts elsewhere: jump there with the laser off, then
    /// keep sampling. Takes no sample period of its own.
    Jump {
        /// Where the previous path ended, mm.
        from_mm: [f64; 2],
        /// Start of the next path, mm.
        to_mm: [f64; 2],
    },
    /// Nothing queued: holding at this position (laser off).
    Idle {
        /// Board x, mm.
        x_mm: f32,
        /// Board y, mm.
        y_mm: f32,
    },
}

/// Why [`PathPlanner::fill`] stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BlockEnd {
    /// The block is full of marking samples.
    Full,
    /// A jump is due (see [`MarkSample::Jump`]); the samples before it are
    /// valid.
    Jump {
        /// Where the path ended, mm.
        from_mm: [f64; 2],
        /// Start of the next path, mm.
        to_mm: [f64; 2],
    },
    /// The buffer ran empty; the spot stopped at the last end point.
    Idle,
}

/// GRBL-style look-ahead planner and sampler with room for `CAP` blocks.
///
/// `CAP` must be at least [`MIN_CAPACITY`] (checked at compile time):
///
/// ```compile_fail
/// use galvo_planner::path::{MarkLimits, PathPlanner};
/// let limits = MarkLimits { speed_mm_s: 1000.0, accel_mm_s2: 1e5, junction_deviation_mm: 0.01, ts_s: 1e-5 };
/// let _too_small = PathPlanner::<0>::new(limits, [0.0, 0.0]);
/// ```
#[derive(Debug, Clone)]
pub struct PathPlanner<const CAP: usize> {
    limits: MarkLimits,
    feed_mm_s: f64,
    /// The blocks not yet running (the running one is in `exec`).
    plan: Lookahead<CAP, Shape>,
    /// End of the last added geometry.
    pen: [f64; 2],
    /// Whether the next segment starts a new path (after a jump / at start).
    next_starts_path: bool,
    exec: Exec,
    /// Last emitted position.
    position: [f32; 2],
}

/// The planner buffer must hold at least this many blocks (one segment;
/// the backward pass always ends the buffer at rest, so fewer blocks only
/// shorten the look-ahead of a streamed path, never break it).
pub const MIN_CAPACITY: usize = 1;

impl<const CAP: usize> PathPlanner<CAP> {
    const CAPACITY_OK: () = assert!(CAP >= MIN_CAPACITY, "PathPlanner needs CAP >= 1");

    /// An empty planner with the spot at rest at `start_mm`.
    pub fn new(limits: MarkLimits, start_mm: [f64; 2]) -> Result<Self, Error> {
        let () = Self::CAPACITY_OK;
        limits.validate()?;
        let start_mm = finite_point("start_mm", start_mm)?;
        let plan = Lookahead::new(limits.junction_deviation_mm)
            .map_err(|e| planner_error(e, limits.junction_deviation_mm))?;
        Ok(Self {
            limits,
            feed_mm_s: limits.speed_mm_s,
            plan,
            pen: start_mm,
            next_starts_path: true,
            exec: IDLE_EXEC,
            position: [start_mm[0] as f32, start_mm[1] as f32],
        })
    }

    /// The limits.
    pub fn limits(&self) -> &MarkLimits {
        &self.limits
    }

    /// Marking speed for the following segments (capped at the limit).
    pub fn set_feed_mm_s(&mut self, feed_mm_s: f64) -> Result<(), Error> {
        let f = positive(feed_mm_s, "feed_mm_s")?;
        self.feed_mm_s = f.min(self.limits.speed_mm_s);
        Ok(())
    }

    /// Blocks in the buffer (including the running one).
    pub fn len(&self) -> usize {
        self.plan.len() + usize::from(self.exec.active)
    }
    /// True when no block is buffered.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Free block slots.
    pub fn free_slots(&self) -> usize {
        CAP - self.len()
    }
    /// End of the last added segment: where the next one starts, mm.
    pub fn pen_mm(&self) -> [f64; 2] {
        self.pen
    }
    /// Last emitted spot position, mm.
    pub fn position_mm(&self) -> [f32; 2] {
        self.position
    }
    /// True when nothing is buffered and the spot is at rest.
    pub fn is_idle(&self) -> bool {
        self.plan.is_empty() && !self.exec.active
    }
}

/// The planner's refusal as this crate's error (`value`: what was
/// offered, mm).
fn planner_error(e: LookaheadError, value: f64) -> Error {
    match e {
        LookaheadError::Full => Error::BufferFull,
        LookaheadError::InvalidBlock => Error::NotPositive {
            name: "length_mm",
            value,
        },
        LookaheadError::InvalidConfig => Error::NotPositive {
            name: "junction_deviation_mm",
            value,
        },
    }
}

/// Checks both coordinates of a point (mm) for NaN/∞.
fn finite_point(name: &'static str, p: [f64; 2]) -> Result<[f64; 2], Error> {
    finite(p[0], name)?;
    finite(p[1], name)?;
    Ok(p)
}

#[cfg(test)]
mod tests;
