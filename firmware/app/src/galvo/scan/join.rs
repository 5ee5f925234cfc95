//! Strokes continued across requests: a stroke sent as a continuation
//! ([`StrokeCm::continuing`]) that starts where the running stroke's
//! look-ahead path planner ends is joined to it in the prep stage — its
//! lines pushed into that planner while it samples — instead of being
//! marked on its own. The contour then runs without a laser off/on or a
//! stop at the joint: the planner still plans every known line to end at
//! rest, so a continuation that comes too late only means the stroke ends
//! there (dark after its laser-off delay) and the continuation is marked
//! as a stroke of its own. The running job's `Done` is reported when the
//! sampler reaches the joined lines; the job then runs on as the joined
//! one (its `Done` at the end, or at the next join).

use kinematics_core::PointMm;

use super::state::Joining;
use super::{GalvoLoop, Job, ScanPhase};
use crate::domain::{Figure, Segment, StrokeCm, Unit};
use crate::galvo::link::GalvoEvent;

/// The continuation stroke of `job`, if it is one.
fn continuation(job: &Job) -> Option<&StrokeCm> {
    match job {
        Job::Path(Figure::Stroke(stroke), _) if stroke.continues() => Some(stroke),
        _ => None,
    }
}

impl GalvoLoop {
    /// Whether the running stroke can still take more lines: being
    /// jumped to, settled on or marked, not stopped, its planner not run
    /// dry.
    fn running_stroke_open(&self) -> bool {
        let open_phase = self.active.as_ref().is_some_and(|a| {
            !a.cancelled
                && matches!(
                    a.phase,
                    ScanPhase::Jumping | ScanPhase::Settling | ScanPhase::Marking
                )
        });
        open_phase
            && self.running
            && self
                .steps
                .get(0)
                .and_then(|step| step.marker.as_ref())
                .is_some_and(|m| m.as_ref().is_ok_and(|p| !p.is_idle()))
    }

    /// Whether the prep stage leaves `job` unprepared for now: a
    /// continuation of the stroke before it, which will be joined to it
    /// (or prepared on its own once that stroke has ended).
    pub(super) fn waits_to_join(&self, job: &Job) -> bool {
        continuation(job).is_some()
            && (self.steps.len() > self.started() || self.running_stroke_open())
    }

    /// Joins the next queued job to the running stroke when it continues
    /// it and fits the planner; `true` when it did (the half's prep).
    #[inline(never)]
    pub(super) fn join_next_piece(&mut self) -> bool {
        let Some(&(seq, job)) = self.queue.front() else {
            return false;
        };
        let Job::Path(path, speed_mm_s) = job else {
            return false;
        };
        if continuation(&job).is_none()
            || self.joining.is_some()
            || self.steps.len() != 1
            || !self.running_stroke_open()
        {
            return false;
        }
        let Some(stroke) = path.stroke(0, Unit::GalvoMm) else {
            return false;
        };
        let Some(Segment::Line { to: [x, y] } | Segment::Arc { end: [x, y], .. }) =
            stroke.segments.last().copied()
        else {
            return false;
        };
        // Where the sampler lands: the end in f32 (as a prepared step).
        let end = PointMm {
            x_mm: f64::from(x as f32),
            y_mm: f64::from(y as f32),
        };
        let Ok(end_rad) = self.angles_for(end) else {
            return false;
        };
        let speed = self.marking_speed_mm_s(speed_mm_s);
        let Some(planner) = self
            .steps
            .get_mut(0)
            .and_then(|step| step.marker.as_mut())
            .and_then(|m| m.as_mut().ok())
        else {
            return false;
        };
        let [px, py] = planner.pen_mm();
        let at_pen = libm::fabs(px - stroke.start[0]) + libm::fabs(py - stroke.start[1]) < 1e-6;
        if !at_pen || planner.free_slots() < stroke.segments.len() {
            return false;
        }
        let before = planner.len();
        let _ = planner.set_feed_mm_s(speed);
        for segment in &stroke.segments {
            let to = match *segment {
                Segment::Line { to } | Segment::Arc { end: to, .. } => to,
            };
            // Room and finite points were checked: cannot fail.
            let _ = planner.line_to(to);
        }
        let blocks = planner.len().saturating_sub(before) as u8;
        if let Some(step) = self.steps.get_mut(0) {
            step.end_rad = end_rad;
        }
        self.active_end_rad = end_rad;
        self.queue.pop_front();
        self.joining = Some(Joining { seq, job, blocks });
        self.work.strokes_prepared += 1;
        true
    }

    /// Planner blocks of the continuation joined and not reached yet.
    pub(super) fn joined_blocks(&self) -> usize {
        self.joining.map_or(0, |j| usize::from(j.blocks))
    }

    /// After marking samples: when the sampler has reached the joined
    /// continuation's blocks (`left` blocks remain in the planner), the
    /// running job is done and the continuation runs on as the job. Out
    /// of line: it runs once per marking run, kept out of the refill's
    /// per-sample code.
    #[inline(never)]
    pub(super) fn reach_joined(&mut self, left: usize, on_event: &mut impl FnMut(GalvoEvent)) {
        let Some(joining) = self.joining else {
            return;
        };
        if left > usize::from(joining.blocks) {
            return;
        }
        self.joining = None;
        if let Some(a) = self.active.as_mut() {
            on_event(GalvoEvent::Done { seq: a.seq });
            a.seq = joining.seq;
            a.job = joining.job;
        }
    }
}

#[cfg(test)]
mod tests;
