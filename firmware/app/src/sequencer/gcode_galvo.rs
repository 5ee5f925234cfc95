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
//! Feed hold during a stroke: the galvo brakes along it, dark, as for a
//! single block; `~` marks the stroke again from its start (today's rule
//! for the step in flight, which for a joined stroke is its first block).
//! `target both` keeps one step per request: the gimbal cannot follow a
//! galvo stroke.

use super::gcode_motion::{cm, point_at};
use super::machine::{ActionSink, Core};
use crate::domain::{Figure, StrokeCm};
use crate::galvo::GalvoRequest;
use crate::grbl::{Block, PointMm};

/// Most chords of an arc counted when joining it (more never fit).
const MAX_ARC_CHORDS: u32 = 100_000;

/// The stroke in flight on the galvo: what its "done" completes.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct GalvoStroke {
    /// Its galvo request number.
    seq: Option<u32>,
    /// Last step of the block in flight it marks.
    last_index: u32,
    /// Whole blocks from the front of the queue it marks after that.
    joined: u8,
}

impl Core {
    /// The galvo's request for the G-code step from `from` to `to` at
    /// `feed` (mm/min), `lit` or dark, with its number; `None` when it
    /// could not be sent (the sequencer stopped).
    pub(super) fn gcode_galvo_send(
        &mut self,
        from: PointMm,
        to: PointMm,
        feed: Option<f64>,
        lit: bool,
        out: &mut dyn ActionSink,
    ) -> Option<u32> {
        self.next_seq = self.next_seq.wrapping_add(1);
        let seq = self.next_seq;
        let stroke = if lit && !self.actuator.uses_gimbal() {
            self.gcode_galvo_stroke(from)
        } else {
            None
        };
        let request = match (stroke, lit) {
            (Some((line, feed_mm_min, mut record)), _) => {
                record.seq = Some(seq);
                self.gcode.galvo = record;
                GalvoRequest::Path {
                    seq,
                    path: Figure::Stroke(line),
                    mark_speed_mm_s: Some(
                        (self.gcode_galvo_feed_mm_min(feed_mm_min) / 60.0) as f32,
                    ),
                }
            }
            (None, true) => GalvoRequest::Path {
                seq,
                path: Figure::Line {
                    from: cm(from),
                    to: cm(to),
                },
                mark_speed_mm_s: feed.map(|f| (self.gcode_galvo_feed_mm_min(f) / 60.0) as f32),
            },
            (None, false) => {
                let [x_mm, y_mm] = cm(to).galvo_mm();
                GalvoRequest::Point {
                    seq,
                    x_mm,
                    y_mm,
                    dwell_us: 0,
                }
            }
        };
        self.send_galvo(request, out).then_some(seq)
    }

    /// The stroke from `from` through what is left of the block in
    /// flight and the lit blocks queued after it, its feed (the slowest,
    /// mm/min) and what it covers; `None` when the block in flight is not
    /// a feed move.
    fn gcode_galvo_stroke(&self, from: PointMm) -> Option<(StrokeCm, f64, GalvoStroke)> {
        let c = self.gcode.motion.current?;
        let mut feed = feed_of(&c.block)?;
        let mut stroke = StrokeCm::new(cm(from))?;
        let mut record = GalvoStroke {
            seq: None,
            last_index: c.count,
            joined: 0,
        };
        let tolerance = self.gcode.values.arc_tolerance_mm;
        if c.index > 1 || !push_block(&mut stroke, &c.block, tolerance) {
            // Part of the block was drawn already (or it does not fit):
            // its steps (an arc's chords) from here, up to the room.
            for k in c.index..=c.count {
                if !stroke.line_to(cm(point_at(&c.block, k, c.count))) {
                    break;
                }
                record.last_index = k;
            }
            if record.last_index < c.count {
                return Some((stroke, feed, record));
            }
        }
        for block in self.gcode.motion.queue.iter() {
            let Some(block_feed) = feed_of(block).filter(|_| self.lights(block)) else {
                break;
            };
            if !push_block(&mut stroke, block, tolerance) {
                break;
            }
            feed = feed.min(block_feed);
            record.joined += 1;
        }
        Some((stroke, feed, record))
    }

    /// The galvo finished request `seq`: when it was the stroke in
    /// flight, the block in flight moves to the stroke's last step, and
    /// the blocks joined to it leave the queue (the last one becomes the
    /// block in flight, at its end). The caller then finishes the step.
    pub(super) fn gcode_galvo_stroke_done(&mut self, seq: u32, out: &mut dyn ActionSink) {
        let record = core::mem::take(&mut self.gcode.galvo);
        if record.seq != Some(seq) {
            return;
        }
        let motion = &mut self.gcode.motion;
        let Some(c) = motion.current.as_mut() else {
            return;
        };
        c.index = record.last_index;
        for _ in 0..record.joined {
            if let Some(block) = motion.queue.pop_front() {
                (c.block, c.index, c.count) = (block, 1, 1);
            }
        }
        if record.joined > 0 {
            self.grbl_take_owed(out);
        }
    }
}

/// Adds feed move `block` (from where the stroke ends) to `stroke`: a
/// line, or an arc as its chords within `arc_tolerance_mm` (`$12`);
/// `false` (the stroke as it was) when it does not fit.
fn push_block(stroke: &mut StrokeCm, block: &Block, arc_tolerance_mm: f64) -> bool {
    match *block {
        Block::Line { to, .. } => stroke.line_to(cm(to)),
        Block::Arc { arc, .. } => {
            let chords = arc.segment_count(arc_tolerance_mm, MAX_ARC_CHORDS);
            chords as usize <= stroke.room()
                && (1..=chords).all(|k| stroke.line_to(cm(point_at(block, k, chords))))
        }
        _ => false,
    }
}

/// Programmed feed of a feed move, mm/min.
fn feed_of(block: &Block) -> Option<f64> {
    match *block {
        Block::Line { feed_mm_min, .. } | Block::Arc { feed_mm_min, .. } => Some(feed_mm_min),
        _ => None,
    }
}

#[cfg(test)]
mod tests;
