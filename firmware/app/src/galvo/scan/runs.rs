//! Runs of samples: each phase fills as many samples of the half as it
//! has in a loop of its own, so the per-sample work is only the phase's
//! (integrator and DAC mapping while jumping; path sampler, galvo IK and
//! DAC mapping while marking; a copy while holding) and the state
//! machine runs once per phase change, not once per sample.

use galvo_planner::blocks::LoopIntegrator;
use galvo_planner::{Error as PlannerError, XyJump};

use super::state::JumpCodes;
use super::{GalvoLoop, ScanPhase};
use crate::galvo::dac::DacSample;
use crate::galvo::link::GalvoEvent;

/// Samples computed per block (angles or positions, and codes, on the
/// stack).
pub(super) const BLOCK: usize = 32;

impl GalvoLoop {
    /// Fills the start of `out` with the current phase's samples; returns
    /// how many (at least one when `out` is not empty).
    pub(super) fn phase_run(
        &mut self,
        out: &mut [DacSample],
        on_event: &mut impl FnMut(GalvoEvent),
    ) -> usize {
        match self.phase() {
            ScanPhase::Marking => self.mark_run(out, on_event),
            ScanPhase::Braking => {
                self.work.marked += 1;
                let codes = self.brake_sample();
                self.emit(out, codes, false)
            }
            ScanPhase::Jumping => self.jump_run(out),
            ScanPhase::Idle
            | ScanPhase::Settling
            | ScanPhase::Dwelling
            | ScanPhase::LaserOffDelay => self.held_run(out),
        }
    }

    /// Writes one sample (`codes`, or the last ones when `None`) to the
    /// start of `out`; returns 1 (0 for an empty `out`).
    pub(super) fn emit(
        &mut self,
        out: &mut [DacSample],
        codes: Option<(u16, u16)>,
        laser: bool,
    ) -> usize {
        if let Some((x_code, y_code)) = codes {
            self.last.x_code = x_code;
            self.last.y_code = y_code;
        }
        self.last.laser = laser;
        match out.first_mut() {
            Some(slot) => {
                *slot = self.last;
                1
            }
            None => 0,
        }
    }

    /// The mirrors hold still (settling, dwelling, laser-off delay, or
    /// nothing runs): the rest of the timed phase, or of `out` when
    /// nothing runs, as copies of one sample. Mirrors still moving (a
    /// cancelled job's jump) go through [`Self::jump_run`].
    pub(super) fn held_run(&mut self, out: &mut [DacSample]) -> usize {
        if !self.mirrors.is_idle() {
            return self.jump_run(out);
        }
        let phase = self.phase();
        let n = match self.active.as_mut() {
            Some(a) => {
                let n = out.len().min(a.samples_left as usize).max(1);
                a.samples_left = a.samples_left.saturating_sub(n as u32);
                n
            }
            None => out.len(),
        };
        // An idle integrator returns its rest position and does not change.
        let [x_rad, y_rad] = self.mirrors.step();
        let codes = self
            .sample_map
            .angles_to_codes(x_rad, y_rad)
            .map(|c| (c.x.code, c.y.code));
        self.emit(out, codes, phase == ScanPhase::Dwelling);
        self.work.held += n as u32;
        let sample = self.last;
        out.iter_mut().take(n).for_each(|s| *s = sample);
        n.min(out.len())
    }

    /// Jumping, laser off: the prepared codes copied, or the integrator's
    /// angles block by block, each mapped to DAC codes, until the jump
    /// lands or `out` is full.
    fn jump_run(&mut self, out: &mut [DacSample]) -> usize {
        let n = out.len().min(self.mirrors.remaining_samples()).max(1);
        if let Some(cursor) = self.jump_cursor {
            let codes = self.jump_codes.codes.get(cursor..).unwrap_or_default();
            let n = n.min(codes.len()).min(out.len());
            let (codes, out) = (codes.get(..n).unwrap_or_default(), &mut out[..n]);
            write_codes(out, codes, false);
            if let Some(&[x_code, y_code]) = codes.last() {
                self.last = DacSample {
                    x_code,
                    y_code,
                    laser: false,
                };
            }
            self.mirrors.skip(n);
            self.jump_cursor = Some(cursor + n);
            self.work.jump_copied += n as u32;
            if n > 0 {
                return n;
            }
            // Out of codes before the integrator landed (cannot happen:
            // both count the plan's samples): step it from here.
            self.jump_cursor = None;
        }
        let mut angles = [[0.0f32; 2]; BLOCK];
        let mut codes = [[0u16; 2]; BLOCK];
        let mut last = [self.last.x_code, self.last.y_code];
        self.work.jump_stepped += n as u32;
        for chunk in out.get_mut(..n).unwrap_or_default().chunks_mut(BLOCK) {
            let angles = angles.get_mut(..chunk.len()).unwrap_or_default();
            galvo_planner::blocks::fill_jump(&mut self.mirrors, angles);
            // Angles stay inside the checked range; on a conversion error
            // the last codes hold rather than output garbage.
            last = self.sample_map.angles_block(angles, &mut codes, last);
            write_codes(chunk, &codes, false);
        }
        self.last = DacSample {
            x_code: last[0],
            y_code: last[1],
            laser: false,
        };
        n.min(out.len())
    }
}

/// `out[i]` ← `codes[i]` with the laser bit `laser`.
#[inline(always)]
pub(super) fn write_codes(out: &mut [DacSample], codes: &[[u16; 2]], laser: bool) {
    for (slot, &[x_code, y_code]) in out.iter_mut().zip(codes) {
        *slot = DacSample {
            x_code,
            y_code,
            laser,
        };
    }
}

/// Queues `jump` on the loop's `mirrors`; with its `codes` computed by
/// the prep stage the refill copies them (into `running`, from
/// `cursor`) and the integrator only counts the samples, else the
/// refill steps the integrator.
pub(super) fn queue_jump(
    mirrors: &mut LoopIntegrator,
    running: &mut JumpCodes,
    cursor: &mut Option<usize>,
    jump: &XyJump<3>,
    codes: Option<&JumpCodes>,
) -> Result<(), PlannerError> {
    match codes {
        Some(codes) if codes.len == jump.samples() => {
            mirrors.queue_jump_skipped(jump)?;
            running.clone_from(codes);
            *cursor = Some(0);
        }
        _ => {
            mirrors.queue_jump(jump)?;
            *cursor = None;
        }
    }
    Ok(())
}
