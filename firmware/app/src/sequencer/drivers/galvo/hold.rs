//! Feed hold of a stroke on the galvo (see [`super`]): the galvo brakes
//! along it, dark, and reports where marking ended; the blocks (arc
//! chords) marked by then are finished, the block in progress is left at
//! the stop point, so `~` marks only what is left of the contour.

use crate::galvo::MarkStop;
use crate::grbl::PointMm;
use crate::sequencer::drivers::galvo::Cursor;
use crate::sequencer::gcode::queue::{Hold, point_at};
use crate::sequencer::machine::{ActionSink, Core};

/// A stop closer than this to the end of its step (mm) ends the step.
const AT_END_MM: f64 = 1e-3;

impl Core {
    /// `!` with a stroke in flight on the galvo alone: the hold stays
    /// stopping until the galvo reports where marking ended. `true` when
    /// it does.
    pub(in crate::sequencer) fn gcode_galvo_hold(&mut self) -> bool {
        let c = self.gcode.motion.current;
        let lockstep = self.drivers().lockstep();
        let record = &mut self.jobs.galvo;
        // (Still waiting after a `!`, `~` before the report, `!`.)
        record.stopping |=
            !lockstep && c.is_some_and(|c| c.galvo_seq.is_some() && c.galvo_seq == record.seq);
        record.stopping
    }

    /// A stop or reset dropped the hold: no report is awaited.
    pub(in crate::sequencer) fn gcode_galvo_hold_dropped(&mut self) {
        self.jobs.galvo.stopping = false;
    }

    /// The galvo stopped (`at`: where marking ended, if it marked): when a
    /// hold waits for it, what was marked is done and the hold is held
    /// (or, resumed meanwhile, goes on from the stop point).
    #[inline(never)]
    pub(in crate::sequencer) fn gcode_galvo_stopped(
        &mut self,
        at: Option<MarkStop>,
        out: &mut dyn ActionSink,
    ) {
        if !self.jobs.galvo.stopping {
            return;
        }
        // The galvo dropped the pieces sent ahead.
        let record = core::mem::take(&mut self.jobs.galvo);
        let piece = at.and_then(|at| match record.seq == Some(at.seq) {
            true => Some((at, Cursor { pos: 0, index: 0 })),
            false => (record.ahead.iter().flatten())
                .find(|a| a.seq == at.seq)
                .map(|a| (at, a.start)),
        });
        if let Some((at, start)) = piece {
            self.gcode_galvo_rest_at(start, at, out);
        }
        // Held; `~` came while stopping: resumed at once.
        let motion = &mut self.gcode.motion;
        let resumed = motion.hold == Hold::None;
        motion.hold = Hold::Held;
        if resumed {
            self.grbl_resume(out);
        }
    }

    /// Marking ended at `at`, on its line of the piece starting at
    /// `start`: the blocks before it leave the queue, its step is the one
    /// in flight, from the stop point (done when it is the step's end).
    fn gcode_galvo_rest_at(&mut self, start: Cursor, at: MarkStop, out: &mut dyn ActionSink) {
        let Some(stop) = self.gcode_galvo_locate(start, u32::from(at.line)) else {
            return;
        };
        let Some((block, count)) = self.gcode_galvo_block(stop.pos) else {
            return;
        };
        let point = PointMm {
            x_mm: f64::from(at.x_mm),
            y_mm: f64::from(at.y_mm),
        };
        let motion = &mut self.gcode.motion;
        let Some(mut c) = motion.current else { return };
        for _ in 0..stop.pos {
            motion.queue.pop_front();
        }
        (c.block, c.index, c.count) = (block, stop.index, count);
        motion.position = point;
        if point.distance_to(point_at(&block, c.index, count)) < AT_END_MM {
            c.index += 1;
        }
        motion.current = (c.index <= c.count).then_some(c);
        // The blocks left the queue: a line waiting for room is queued.
        self.grbl_take_owed(out);
    }

    /// Step `line` (from 0) of the piece starting at `start` (index 0:
    /// the block in flight's step): its block and step.
    fn gcode_galvo_locate(&self, start: Cursor, mut line: u32) -> Option<Cursor> {
        let index = match start.index {
            0 => self.gcode.motion.current?.index,
            index => index,
        };
        let mut at = Cursor {
            pos: start.pos,
            index,
        };
        loop {
            let (_, count) = self.gcode_galvo_block(at.pos)?;
            let left = (count + 1).saturating_sub(at.index);
            if line < left {
                at.index += line;
                return Some(at);
            }
            line -= left;
            at = Cursor {
                pos: at.pos + 1,
                index: 1,
            };
        }
    }
}
