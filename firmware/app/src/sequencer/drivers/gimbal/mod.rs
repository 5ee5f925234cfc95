//! G-code on the gimbal through grbl's look-ahead planner: every period
//! the block running (what is left of it, entered at the speed it has)
//! and the motion blocks queued behind it (up to [`PLAN_BLOCKS`], to the
//! first that must start from rest) are planned by
//! [`kinematics_core::lookahead::Lookahead`] in board mm (cruise at F —
//! G0 at the rate limit — capped by `$110` and the servo speed;
//! acceleration `$120` capped by the servos' [`GIMBAL_ACCEL_DEG_S2`];
//! junctions by `$11`): the plan gives the running block's exit speed.
//! Planned afresh each period, nothing of it stays in the sequencer's
//! state (its stack copies of it are what the 14 KiB ceiling counts). The
//! block running is
//! followed at [`STREAM_PERIOD_MS`] by a [`SpeedCursor`]: every period
//! one servo move to the next point of the planned profile, timed to the
//! period (each move supersedes the one before, so the servos never stop
//! between points). A tick that reaches a block's end goes exactly to it
//! (corners are not cut) and the next block goes on at the junction speed;
//! only a block ending at rest (queue empty, dwell, pause, end, a
//! reversal) waits for arrival within 0.1° and the settle. A feed hold
//! brakes along the path at the limit (dark) and `~` goes on from the
//! point it stopped at; the feed override scales the cruise on the fly.

use kinematics_core::lookahead::SpeedCursor;

/// The streaming period, ms (the servos' shortest move ramp).
pub(in crate::sequencer) const STREAM_PERIOD_MS: u64 = 20;
/// Joint acceleration the servos follow, °/s² (their speed within 0.1 s).
pub(in crate::sequencer) const GIMBAL_ACCEL_DEG_S2: f64 = 2000.0;
/// Blocks planned each period: the block running and those behind it.
const PLAN_BLOCKS: usize = 8;
/// Shortest tick, ms (a block end just past the previous tick).
const MIN_TICK_MS: f64 = 2.0;

/// The block being followed.
#[derive(Debug, Clone)]
pub(in crate::sequencer) struct Stream {
    /// Following the running block (`None`: at rest, or its final move).
    cursor: Option<SpeedCursor>,
    /// Highest cruise of the running block (servo speed, `$110`), mm/s.
    cap_mm_s: f64,
    /// The joint degrees per mm of the blocks planned.
    deg_per_mm: deg_per_mm::DegPerMm<PLAN_BLOCKS>,
}

impl Stream {
    pub(in crate::sequencer) const fn new() -> Self {
        Self {
            cursor: None,
            cap_mm_s: 0.0,
            deg_per_mm: deg_per_mm::DegPerMm::new(),
        }
    }

    /// Forgets the block followed (a stop, a reset, an alarm).
    #[inline(never)]
    pub(in crate::sequencer) fn clear(&mut self) {
        self.cursor = None;
    }

    /// Whether a block is being followed.
    #[inline(never)]
    pub(in crate::sequencer) fn is_following(&self) -> bool {
        self.cursor.is_some()
    }

    /// Forgets the joint degrees per mm worked out (the geometry changed).
    pub(in crate::sequencer) fn geometry_changed(&mut self) {
        self.deg_per_mm.clear();
    }

    /// Speed now, mm/s (0 at rest).
    #[inline(never)]
    pub(in crate::sequencer) fn speed_mm_s(&self) -> f64 {
        self.cursor.map_or(0.0, |c| c.speed)
    }
}

mod cache;
mod deg_per_mm;
mod plan;
pub(in crate::sequencer) mod points;
pub(in crate::sequencer) mod step;
mod stream;
