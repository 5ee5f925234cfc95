//! The galvo loop's state types (no behaviour of the loop): the spot's
//! motion, prepared steps, a joined continuation and the stop trace.

use galvo_planner::blocks::PRECOMPUTED_JUMP;
use galvo_planner::{PathPlanner, XyJump};

use super::types::{GalvoError, Job, MARK_BLOCKS};
use crate::galvo::link::MarkStop;

/// Steps prepared ahead of the refill (a step takes at least the laser
/// delays and its jump; four cover a half buffer of the shortest jobs).
pub(super) const PREP_DEPTH: usize = 4;

/// The spot while marking or braking: position (mm) and its change over
/// the last sample (mm per sample).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Motion {
    pub(super) position_mm: [f32; 2],
    pub(super) step_mm: [f32; 2],
    /// Speed lost per braking sample, mm per sample (accel · Ts²).
    pub(super) brake_mm: f32,
}

/// A stroke loaded into the look-ahead path planner, or why it was refused.
pub(super) type LoadedStroke = Result<PathPlanner<MARK_BLOCKS>, GalvoError>;

/// A jump's DAC codes, sample by sample.
#[derive(Debug, Clone)]
pub(super) struct JumpCodes {
    /// Samples of the jump.
    pub(super) len: usize,
    /// `[x, y]` codes; the first `len` are the jump's.
    pub(super) codes: [[u16; 2]; PRECOMPUTED_JUMP],
}

impl JumpCodes {
    /// No samples.
    pub(super) const EMPTY: Self = Self {
        len: 0,
        codes: [[0; 2]; PRECOMPUTED_JUMP],
    };
}

/// One prepared step: the jump to its start and, for a stroke, the loaded
/// path planner.
#[derive(Debug, Clone)]
pub(super) struct Prepared {
    pub(super) seq: u32,
    pub(super) job: Job,
    pub(super) stroke: usize,
    /// Whether this step starts a queued job (its stroke 0).
    pub(super) starts_job: bool,
    /// Both axes' jump plans, or why the jump was refused.
    pub(super) jump: Result<XyJump<3>, GalvoError>,
    /// The jump's DAC codes, computed here when it is short enough
    /// (the refill copies them instead of stepping the integrator).
    pub(super) jump_codes: Option<JumpCodes>,
    /// The stroke, for a path step.
    pub(super) marker: Option<LoadedStroke>,
    /// Mirror angles where this step leaves the mirrors, rad.
    pub(super) end_rad: [f64; 2],
}

impl Prepared {
    /// Whether the job goes on after this step (the step was planned).
    pub(super) fn continues(&self) -> bool {
        self.jump.is_ok() && !matches!(self.marker, Some(Err(_)))
    }
}

/// A continuation joined to the running stroke, not reached yet.
#[derive(Debug, Clone, Copy)]
pub(super) struct Joining {
    pub(super) seq: u32,
    pub(super) job: Job,
    /// Planner blocks it added (the last ones in the planner).
    pub(super) blocks: u8,
}

/// Halves noted (the newest first).
pub(super) const HALVES: usize = 4;
/// The notes, and a stop's report waiting for the mirrors to rest.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Trace {
    pub(super) halves: [Option<MarkStop>; HALVES],
    /// `Some`: a stop is to be reported, with this note.
    pub(super) due: Option<Option<MarkStop>>,
}
