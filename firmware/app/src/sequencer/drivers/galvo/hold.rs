//! Feed hold of a stroke on the galvo (see [`super`]): the galvo brakes
//! along it, dark, and reports where marking ended; the blocks (arc
//! chords) marked by then are finished, the block in progress is left at
//! the stop point, so `~` marks only what is left of the contour.

use crate::galvo::MarkStop;
use crate::grbl::PointMm;
use crate::sequencer::drivers::galvo::gcode::block_at;
use crate::sequencer::drivers::galvo::{Cursor, GalvoStroke};
use crate::sequencer::drivers::stage::Stage;
use crate::sequencer::gcode::queue::{Current, point_at};

/// A stop closer than this to the end of its step (mm) ends the step.
const AT_END_MM: f64 = 1e-3;

impl GalvoStroke {
    /// `!` with a stroke in flight on the galvo alone (`current`: the
    /// block in flight; `lockstep`: several drivers draw): the hold stays
    /// stopping until the galvo reports where marking ended. `true` when
    /// it does.
    pub(in crate::sequencer) fn hold(&mut self, current: Option<Current>, lockstep: bool) -> bool {
        // (Still waiting after a `!`, `~` before the report, `!`.)
        self.stopping |=
            !lockstep && current.is_some_and(|c| c.galvo_seq.is_some() && c.galvo_seq == self.seq);
        self.stopping
    }

    /// A stop or reset dropped the hold: no report is awaited.
    pub(in crate::sequencer) fn hold_dropped(&mut self) {
        self.stopping = false;
    }

    /// The galvo stopped (`at`: where marking ended, if it marked): when a
    /// hold waits for it, what was marked is done (the caller then holds,
    /// or, resumed meanwhile, goes on from the stop point). `None` when no
    /// hold waits; else whether blocks left the queue (a line waiting for
    /// room is then queued).
    pub(in crate::sequencer) fn stopped(
        &mut self,
        st: &mut Stage,
        at: Option<MarkStop>,
    ) -> Option<bool> {
        if !self.stopping {
            return None;
        }
        // The galvo dropped the pieces sent ahead.
        let record = core::mem::take(self);
        let piece = at.and_then(|at| match record.seq == Some(at.seq) {
            true => Some((at, Cursor { pos: 0, index: 0 })),
            false => (record.ahead.iter().flatten())
                .find(|a| a.seq == at.seq)
                .map(|a| (at, a.start)),
        });
        Some(piece.is_some_and(|(at, start)| rest_at(st, start, at)))
    }
}

/// Marking ended at `at`, on its line of the piece starting at `start`:
/// the blocks before it leave the queue, its step is the one in flight,
/// from the stop point (done when it is the step's end). `true` when it
/// moved the queue on.
fn rest_at(st: &mut Stage, start: Cursor, at: MarkStop) -> bool {
    let Some(stop) = locate(st, start, u32::from(at.line)) else {
        return false;
    };
    let Some((block, count)) = block_at(st, stop.pos) else {
        return false;
    };
    let point = PointMm {
        x_mm: f64::from(at.x_mm),
        y_mm: f64::from(at.y_mm),
    };
    let motion = &mut st.gcode.motion;
    let Some(mut c) = motion.current else {
        return false;
    };
    for _ in 0..stop.pos {
        motion.queue.pop_front();
    }
    (c.block, c.index, c.count) = (block, stop.index, count);
    motion.position = point;
    if point.distance_to(point_at(&block, c.index, count)) < AT_END_MM {
        c.index += 1;
    }
    motion.current = (c.index <= c.count).then_some(c);
    true
}

/// Step `line` (from 0) of the piece starting at `start` (index 0: the
/// block in flight's step): its block and step.
fn locate(st: &Stage, start: Cursor, mut line: u32) -> Option<Cursor> {
    let index = match start.index {
        0 => st.gcode.motion.current?.index,
        index => index,
    };
    let mut at = Cursor {
        pos: start.pos,
        index,
    };
    loop {
        let (_, count) = block_at(st, at.pos)?;
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
