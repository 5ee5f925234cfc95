//! The galvo loop's per-sample blocks as concrete functions of this
//! crate.
//!
//! The firmware builds this crate for speed but the application for
//! size, and generic code (the integrator's and the path planner's
//! loops) is compiled in the crate that names the types, with that
//! crate's size settings (calls outlined, nothing inlined: 2–3× the
//! instructions on the M4F). These functions fix the types the loop uses,
//! so their loops are compiled here, once, for speed; `#[inline(never)]`
//! keeps them out of the size-built callers.

use crate::error::Error;
use crate::integrator::XyIntegrator;
use crate::path::{MarkSample, PathPlanner};
use crate::plan::XyJump;

/// Jump input samples the loop's integrator holds per axis (10.24 ms at
/// 100 kHz, longer than any full-range time-optimal jump of the reference
/// galvo).
pub const JUMP_CAPACITY: usize = 1024;

/// Blocks of the loop's path planner: the loop loads a whole stroke (at
/// most 4 segments in laser-app's figures, one block each) before marking
/// it, so its look-ahead is the whole stroke. Each block is ~150 B and the
/// loop keeps five planners (the running step and four prepared).
pub const MARK_BLOCKS: usize = 4;

/// Longest jump (samples) whose angles [`jump_angles`] computes ahead of
/// time (the reference galvo's 160 mm diagonal jump takes 49 samples, its
/// full field about 75).
pub const PRECOMPUTED_JUMP: usize = 96;

/// The rigid two-axis integrator the galvo loop runs.
pub type LoopIntegrator = XyIntegrator<3, JUMP_CAPACITY>;

/// The path planner the galvo loop marks strokes with.
pub type LoopPathPlanner = PathPlanner<MARK_BLOCKS>;

/// [`XyIntegrator::fill`] for the loop's integrator: the next
/// `out.len()` samples' `[θx, θy]`, rad.
#[inline(never)]
pub fn fill_jump(mirrors: &mut LoopIntegrator, out: &mut [[f32; 2]]) {
    mirrors.fill(out);
}

/// The next marking samples of `planner` (`[x, y]`, mm) until `out` is
/// full or the stroke ends (or a jump is due); returns how many it wrote.
/// The samples [`PathPlanner::next_sample`] gives, bit for bit.
#[inline(never)]
pub fn fill_marks(planner: &mut LoopPathPlanner, out: &mut [[f32; 2]]) -> usize {
    let mut n = 0;
    for slot in out.iter_mut() {
        let MarkSample::Mark { x_mm, y_mm, .. } = planner.next_sample() else {
            break;
        };
        *slot = [x_mm, y_mm];
        n += 1;
    }
    n
}

/// The angles (rad) of every sample of `jump` stepped with the loop's
/// `mirrors` model from rest at the jump's start, `θx` into `x` and `θy`
/// into `y`: what `mirrors`, holding there, steps for it, bit for bit
/// ([`Integrator::plan_angles`](crate::integrator::Integrator::plan_angles)).
/// An axis that lands first holds its target for the other's samples.
/// Returns how many samples (`jump.samples()`).
///
/// Errors: [`Error::QueueFull`] for a jump longer than the buffers,
/// [`Error::ModelMismatch`] for a jump planned on another model.
#[inline(never)]
pub fn jump_angles(
    mirrors: &LoopIntegrator,
    jump: &XyJump<3>,
    x: &mut [f32; PRECOMPUTED_JUMP],
    y: &mut [f32; PRECOMPUTED_JUMP],
) -> Result<usize, Error> {
    let nx = mirrors.x.plan_angles(&jump.x, x)?;
    let ny = mirrors.y.plan_angles(&jump.y, y)?;
    let n = nx.max(ny);
    for (axis, plan, len) in [(x, &jump.x, nx), (y, &jump.y, ny)] {
        // Before a move an axis holds its start, after it its target.
        let held = match len.checked_sub(1).and_then(|last| axis.get(last)) {
            Some(&theta) => theta,
            None => plan.start_state().first().copied().unwrap_or(0.0) as f32,
        };
        axis.iter_mut()
            .take(n)
            .skip(len)
            .for_each(|theta| *theta = held);
    }
    Ok(n)
}
