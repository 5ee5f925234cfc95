//! G-code on the galvo alone: consecutive lit feed moves are marked as
//! one stroke ([`Figure::Stroke`]) by the galvo's look-ahead path planner
//! — one jump, one laser-on delay, corners at the planner's junction
//! speed with the laser on through them, one laser-off delay — instead of
//! one stroke per block.
//!
//! A stroke takes what is left of the block in flight and then whole lit
//! G1/G2/G3 blocks waiting at the front of the queue, up to
//! [`StrokeCm::MAX_SEGMENTS`] lines: a G1 is a line, a G2/G3 its chords
//! within `$12` (exact arcs cost the galvo's prep stage too much, see
//! [`StrokeCm`]). It is marked at the slowest of its
//! blocks' feeds (F × feed override, capped by `galvo.mark_speed_mm_s`).
//! The galvo reports it done once; then its blocks leave the queue
//! together (their slots free, a line waiting for room is answered) and
//! the position moves to its end.
//!
//! A contour longer than one stroke is sent in pieces that continue it
//! ([`StrokeCm::continuing`], up to [`AHEAD_LINES`] lines each, up to
//! [`AHEAD`] of them ahead of the piece in flight): the galvo loop joins
//! each to the stroke it is marking, so the whole contour is one stroke
//! (one laser on/off pair, no stop at the joints); a piece that comes too
//! late is marked as a stroke of its own. Each piece's `Done` still
//! finishes its blocks, then the next piece (already sent) is the one in
//! flight.
//!
//! Feed hold during a stroke ([`hold`]): the gate closes (dark at once),
//! the galvo drops the pieces sent ahead, brakes along the stroke and
//! reports where marking stopped ([`GalvoEvent::Stopped`]: the piece, its
//! line, the point). The hold is stopping (`Hold:1`) until then; the
//! blocks (arc chords) marked by then finish as on `done`, the block in
//! progress stays in flight from the stop point (`MPos`, `Hold:0`), and
//! `~` sends the rest of the contour from there as a new stroke, so
//! nothing marked before the hold is lit again. A report that names no
//! piece of it (nothing lit yet) redoes the step in flight.
//! `target both` keeps one step per request: the gimbal cannot follow a
//! galvo stroke.

use crate::domain::StrokeCm;
use crate::galvo::GalvoConfig;
#[cfg(doc)]
use crate::galvo::GalvoEvent;
use crate::grbl::PointMm;
use crate::settings::{GalvoSettings, JumpPlanner};
use galvo_planner::{Method, RigidParams};

/// Most chords of an arc counted when joining it (more never fit).
const MAX_ARC_CHORDS: u32 = 100_000;
/// Lines of a piece sent ahead: half the loop's path planner, so it joins
/// while the piece before it still has blocks there.
pub(in crate::sequencer) const AHEAD_LINES: usize = StrokeCm::MAX_SEGMENTS / 2;
/// Pieces sent ahead of the one in flight.
const AHEAD: usize = 2;

/// Where a piece starts: step `index` of block `pos` (0: the block in
/// flight; k: the k-th queued one).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Cursor {
    pos: usize,
    index: u32,
}

/// What a piece covers from its start cursor.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Cover {
    /// Last step of its first block it marks.
    last_index: u32,
    /// Whole blocks after that one it marks.
    joined: u8,
    /// Where it ends, mm.
    end: PointMm,
}

/// The stroke in flight on the galvo: what its "done" completes.
#[derive(Debug, Clone, Copy, Default)]
pub(in crate::sequencer) struct GalvoStroke {
    /// Its galvo request number.
    seq: Option<u32>,
    /// What it covers from the block in flight.
    cover: Cover,
    /// Pieces sent ahead, continuing it, oldest first.
    ahead: [Option<Ahead>; AHEAD],
    /// The piece after a finished one, in flight from the next step.
    adopt: Option<Ahead>,
    /// A feed hold waits for the galvo to report where it stopped.
    stopping: bool,
}

/// A piece sent ahead of the one in flight.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Ahead {
    seq: u32,
    start: Cursor,
    cover: Cover,
    lines: u8,
}

/// A piece built: the stroke, its feed (the slowest, mm/min), its cover.
struct Piece {
    stroke: StrokeCm,
    feed: f64,
    cover: Cover,
}

/// Dwell of a goto on the galvo: held until the next command, µs.
const HOLD_US: u32 = u32::MAX;

/// The loop configuration for the user's galvo parameters and the
/// junction deviation (`$11`, mm) its marking planner corners with.
pub fn config_from(settings: &GalvoSettings, junction_deviation_mm: f64) -> GalvoConfig {
    GalvoConfig {
        sample_period_s: settings.sample_period_us * 1e-6,
        galvo: settings.galvo(),
        mirrors: RigidParams {
            kt_nm_per_a: settings.kt_nm_per_a,
            j_kg_m2: settings.j_kg_m2,
            l_h: settings.l_h,
            r_ohm: settings.r_ohm,
            u_max_v: settings.u_max_v,
        },
        method: match settings.planner {
            JumpPlanner::Optimal => Method::TimeOptimal,
            JumpPlanner::Seed => Method::BISECTION,
        },
        laser_on_delay_us: settings.laser_on_delay_us as u32,
        laser_off_delay_us: settings.laser_off_delay_us as u32,
        mark_speed_mm_s: settings.mark_speed_mm_s,
        mark_accel_mm_s2: settings.mark_accel_mm_s2,
        junction_deviation_mm,
    }
}

impl Default for GalvoConfig {
    /// The default galvo parameters ([`GalvoSettings::default`]): 100 kHz,
    /// SPEC geometry and DAC span, reference mirror drive, time-optimal
    /// jumps, 100 µs laser delays, marking at 1 m/s.
    fn default() -> Self {
        let defaults = crate::settings::Settings::default();
        config_from(&defaults.galvo, defaults.gcode_junction_mm)
    }
}

mod ahead;
mod gcode;
mod hold;
pub(in crate::sequencer) mod points;
#[cfg(test)]
mod tests;
