//! The prep stage: grbl's planner → segment prep → stepper ISR, for the
//! galvo. Planning a job's jump (time-optimal, per jump) and loading a
//! stroke into the look-ahead path planner (f64, per stroke) happen here,
//! between half buffers, for the next steps of the queued work; the refill
//! ([`GalvoLoop::refill`]) only steps the plans prepared here. A refill
//! that needs a step nobody prepared holds the mirrors, laser off (counted
//! in [`GalvoLoop::unprepared_samples`]): the laser is never lit without a
//! prepared plan.
//!
//! A step is one jump plus what follows it: a point's dwell, or one stroke
//! of a path. Each step is planned from where the step before it leaves
//! the mirrors (a point's target; a stroke's end point as the path
//! sampler lands on it, in f32), so prepared steps chain without looking
//! at the running loop; the refill checks that chain when it queues the
//! jump and drops the prepared steps if it broke.

use galvo_planner::blocks::{PRECOMPUTED_JUMP, jump_angles};
use galvo_planner::{MarkLimits, MethodKind, PathPlanner, XyJump};
use kinematics_core::PointMm;

use super::state::{JumpCodes, LoadedStroke, PREP_DEPTH, Prepared};
use super::{GalvoError, GalvoLoop, Job};
use crate::domain::{Rotation, Segment, Unit};

/// What comes after a step of `job`: its next stroke, if it has one.
fn next_stroke(job: &Job, stroke: usize) -> Option<usize> {
    match job {
        Job::Path(path, _) => path.stroke(stroke + 1, Unit::GalvoMm).map(|_| stroke + 1),
        Job::Point { .. } => None,
    }
}

impl GalvoLoop {
    /// Prepares the next steps of the queued work (up to `PREP_DEPTH`
    /// ahead): plans their jumps and loads their strokes. Runs between
    /// half buffers, never inside the refill. Returns how many steps it
    /// prepared.
    pub fn prep(&mut self) -> usize {
        self.prep_up_to(PREP_DEPTH)
    }

    /// [`Self::prep`], preparing at most `max_steps` steps (the run loop
    /// prepares one per half buffer, to stay within its window).
    #[inline(never)]
    pub fn prep_up_to(&mut self, max_steps: usize) -> usize {
        if max_steps > 0 && self.join_next_piece() {
            // Joining a continuation is this call's step.
            return 1;
        }
        let mut prepared = 0;
        while prepared < max_steps && self.steps.len() - self.started() < PREP_DEPTH {
            let Some(step) = self.next_unprepared_step() else {
                break;
            };
            let stroke = step.marker.is_some();
            let bisected = match &step.jump {
                Ok(jump) => [&jump.x, &jump.y]
                    .iter()
                    .filter(|plan| plan.method() == MethodKind::Bisection)
                    .count(),
                Err(_) => 0,
            };
            if self.steps.push_back(step).is_err() {
                break;
            }
            self.work.bisection_axes += bisected as u32;
            if stroke {
                self.work.strokes_prepared += 1;
            } else {
                self.work.points_prepared += 1;
            }
            prepared += 1;
        }
        prepared
    }

    /// Steps at the front of [`Self::steps`] already started: the running
    /// one (0 or 1).
    pub(super) fn started(&self) -> usize {
        usize::from(self.running && !self.steps.is_empty())
    }

    /// Samples the refill held dark because the step it needed was not
    /// prepared (since the loop was built).
    pub fn unprepared_samples(&self) -> u32 {
        self.unprepared_samples
    }

    /// Plans the step after the last prepared one (or after the running
    /// step), if there is one.
    fn next_unprepared_step(&self) -> Option<Prepared> {
        let (after, start_rad) = match (self.steps.back(), self.active) {
            (Some(last), _) => (
                Some((last.seq, last.job, last.stroke, last.continues())),
                last.end_rad,
            ),
            (None, Some(a)) if a.cancelled => return None,
            (None, Some(a)) => (Some((a.seq, a.job, a.stroke, true)), self.active_end_rad),
            (None, None) => (None, self.mirrors.end_position_rad()),
        };
        let next_in_job = after.and_then(|(seq, job, stroke, continues)| {
            let stroke = next_stroke(&job, stroke).filter(|_| continues)?;
            Some((seq, job, stroke, false))
        });
        let (seq, job, stroke, starts_job) = match next_in_job {
            Some(step) => step,
            None => {
                let covered = (self.started()..self.steps.len())
                    .filter(|&i| self.steps.get(i).is_some_and(|p| p.starts_job))
                    .count();
                let &(seq, job) = self.queue.iter().nth(covered)?;
                if self.waits_to_join(&job) {
                    return None;
                }
                (seq, job, 0, true)
            }
        };
        Some(self.plan_step(seq, job, stroke, starts_job, start_rad))
    }

    /// Plans the jump from `start_rad` to step `stroke` of `job` and loads
    /// the stroke.
    fn plan_step(
        &self,
        seq: u32,
        job: Job,
        stroke: usize,
        starts_job: bool,
        start_rad: [f64; 2],
    ) -> Prepared {
        let (target_mm, marker, end_mm) = match job {
            Job::Point { target_mm, .. } => (Ok(target_mm), None, None),
            Job::Path(path, speed_mm_s) => match path.stroke(stroke, Unit::GalvoMm) {
                Some(stroke) => (
                    Ok(PointMm::new(stroke.start[0], stroke.start[1])),
                    Some(self.load_stroke(stroke.start, &stroke.segments, speed_mm_s)),
                    stroke.segments.last().map(|s| match *s {
                        Segment::Line { to: end } | Segment::Arc { end, .. } => end,
                    }),
                ),
                None => (Err(GalvoError::Planner), None, None),
            },
        };
        let jump = target_mm.and_then(|target| {
            let target_rad = self.angles_for(target)?;
            (self.jump_planning.plan)(&self.disc, start_rad, target_rad, self.config.method)
                .map(|jump| (jump, target_rad))
        });
        let end_rad = match (&jump, &marker, end_mm) {
            (Err(_), _, _) => start_rad,
            // Where the path sampler lands: the stroke's end in f32 (a
            // closed stroke whose start is exact in f32 ends at its start:
            // the same IK, not computed twice).
            (Ok((_, target_rad)), Some(Ok(_)), Some([x, y])) => {
                let end = PointMm {
                    x_mm: f64::from(x as f32),
                    y_mm: f64::from(y as f32),
                };
                if Ok(end) == target_mm {
                    *target_rad
                } else {
                    self.angles_for(end).unwrap_or(start_rad)
                }
            }
            (Ok((_, target_rad)), _, _) => *target_rad,
        };
        let jump_codes = match &jump {
            Ok((jump, _)) => self.jump_codes(jump),
            Err(_) => None,
        };
        Prepared {
            seq,
            job,
            stroke,
            starts_job,
            jump_codes,
            jump: jump.map(|(jump, _)| jump),
            marker,
            end_rad,
        }
    }

    /// The DAC codes of every sample of `jump` from rest at its start
    /// (`None` for a jump longer than [`PRECOMPUTED_JUMP`]: the refill
    /// steps it).
    fn jump_codes(&self, jump: &XyJump<3>) -> Option<JumpCodes> {
        if jump.samples() == 0 {
            // Already there: nothing to output.
            return None;
        }
        let (mut x, mut y) = ([0.0f32; PRECOMPUTED_JUMP], [0.0f32; PRECOMPUTED_JUMP]);
        let len = jump_angles(&self.mirrors, jump, &mut x, &mut y).ok()?;
        let mut codes = JumpCodes {
            len,
            codes: [[0; 2]; PRECOMPUTED_JUMP],
        };
        let hold = [self.last.x_code, self.last.y_code];
        self.sample_map
            .axes_block(x.get(..len)?, y.get(..len)?, &mut codes.codes, hold);
        Some(codes)
    }

    /// Loads a stroke (its start and segments) into a fresh path planner,
    /// marked at `speed_mm_s` (mm/s, capped by the configured marking
    /// speed; `None`: that speed).
    fn load_stroke(
        &self,
        start: [f64; 2],
        segments: &[Segment],
        speed_mm_s: Option<f32>,
    ) -> LoadedStroke {
        let limits = MarkLimits {
            // The configured speed caps every stroke joined to this one;
            // each marks at its own feed.
            speed_mm_s: self.config.mark_speed_mm_s,
            accel_mm_s2: self.config.mark_accel_mm_s2,
            junction_deviation_mm: self.config.junction_deviation_mm,
            ts_s: self.config.sample_period_s,
        };
        let speed = self.marking_speed_mm_s(speed_mm_s);
        let loaded = PathPlanner::new(limits, start).and_then(|mut planner| {
            planner.set_feed_mm_s(speed)?;
            for segment in segments {
                match *segment {
                    Segment::Line { to } => planner.line_to(to)?,
                    Segment::Arc {
                        end,
                        centre,
                        rotation,
                    } => planner.arc_to(end, centre, rotation == Rotation::Ccw)?,
                }
            }
            // The first block's f64 set-up here, not in the refill.
            planner.prime();
            Ok(planner)
        });
        loaded.map_err(|_| GalvoError::Planner)
    }

    /// The marking speed asked (mm/s), capped by the configured one
    /// (`None`, or not a positive speed: the configured one).
    pub(super) fn marking_speed_mm_s(&self, speed_mm_s: Option<f32>) -> f64 {
        let configured = self.config.mark_speed_mm_s;
        speed_mm_s
            .map(f64::from)
            .filter(|s| s.is_finite() && *s > 0.0)
            .map_or(configured, |s| s.min(configured))
    }

    /// Whether the first step not started is step `stroke` of job
    /// `(seq, job)`.
    pub(super) fn next_prepared_is(&self, seq: u32, job: &Job, stroke: usize) -> bool {
        self.steps
            .get(self.started())
            .is_some_and(|p| p.seq == seq && p.job == *job && p.stroke == stroke)
    }
}

#[cfg(test)]
mod tests;
