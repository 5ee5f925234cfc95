//! Where marking was when a stop closed the gate: after each half buffer
//! the loop notes where the sampler is on the stroke being marked; a stop
//! takes the note of the half the DAC was outputting when the gate closed
//! (the loop computes up to two halves ahead, dark after the close), and
//! once the mirrors are at rest the loop reports it
//! ([`GalvoEvent::Stopped`]), so a G-code feed hold resumes from there
//! instead of marking the stroke again.

use super::state::HALVES;
use super::{GalvoLoop, Job, ScanPhase};
use crate::domain::Figure;
use crate::galvo::link::{GalvoEvent, GalvoLink, MarkStop};

/// The note of the half the DAC output when the gate closed, as the loop
/// sees the close (at the start of its next half): two halves before the
/// newest, whose output began while the loop computed the newest.
const LIT_HALF: usize = 2;

impl GalvoLoop {
    /// After a computed half: notes where the stroke being marked is (a
    /// half that marks nothing keeps the note before it).
    #[inline(never)]
    pub(super) fn trace_half(&mut self) {
        let now = self.marking_now();
        let halves = &mut self.trace.halves;
        halves.copy_within(0..HALVES - 1, 1);
        if now.is_some() {
            halves[0] = now;
        }
    }

    /// A stop: the note of the half that was lit when the gate closed is
    /// reported once the mirrors rest (a second stop before that keeps
    /// it: the notes are cleared).
    pub(super) fn trace_stop(&mut self) {
        let t = &mut self.trace;
        t.due = Some(t.halves[LIT_HALF].or(t.due.flatten()));
        t.halves = [None; HALVES];
    }

    /// Reports a stop once the mirrors rest.
    pub(super) fn report_stopped(&mut self, link: &GalvoLink) {
        if self.active.is_none()
            && let Some(at) = self.trace.due.take()
        {
            let _ = link.events.try_send(GalvoEvent::Stopped(at));
        }
    }

    /// Where the G-code stroke being marked is: its line and the spot.
    fn marking_now(&self) -> Option<MarkStop> {
        let a = self
            .active
            .as_ref()
            .filter(|a| a.phase == ScanPhase::Marking && !a.cancelled)?;
        let Job::Path(Figure::Stroke(stroke), _) = a.job else {
            return None;
        };
        let planner = self
            .steps
            .get(0)
            .filter(|_| self.running)
            .and_then(|step| step.marker.as_ref())
            .and_then(|m| m.as_ref().ok())?;
        // Blocks left of this job: the joined continuation's are after.
        let left = planner.len().saturating_sub(self.joined_blocks());
        let lines = stroke.segments();
        let line = lines.saturating_sub(left).min(lines.saturating_sub(1));
        let [x_mm, y_mm] = self.motion.position_mm;
        Some(MarkStop {
            seq: a.seq,
            line: line as u8,
            x_mm,
            y_mm,
        })
    }
}
