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

use super::gcode_motion::{block_point, cm, point_at};
use super::machine::{ActionSink, Core};
use crate::domain::{Figure, StrokeCm};
#[cfg(doc)]
use crate::galvo::GalvoEvent;
use crate::galvo::GalvoRequest;
use crate::grbl::{Block, PointMm};

/// Most chords of an arc counted when joining it (more never fit).
const MAX_ARC_CHORDS: u32 = 100_000;
/// Lines of a piece sent ahead: half the loop's path planner, so it joins
/// while the piece before it still has blocks there.
pub(super) const AHEAD_LINES: usize = StrokeCm::MAX_SEGMENTS / 2;
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
pub(super) struct GalvoStroke {
    /// Its galvo request number.
    seq: Option<u32>,
    /// What it covers from the block in flight.
    cover: Cover,
    /// Pieces sent ahead, continuing it, oldest first.
    ahead: [Option<ahead::Ahead>; AHEAD],
    /// The piece after a finished one, in flight from the next step.
    adopt: Option<ahead::Ahead>,
    /// A feed hold waits for the galvo to report where it stopped.
    stopping: bool,
}

/// A piece built: the stroke, its feed (the slowest, mm/min), its cover.
struct Piece {
    stroke: StrokeCm,
    feed: f64,
    cover: Cover,
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
        let strokes = lit && !self.drivers().lockstep();
        if let Some(next) = self.gcode.galvo.adopt.take() {
            if strokes && let Some(seq) = self.gcode_galvo_adopt(from, next) {
                return Some(seq);
            }
            // Not the step it was sent for (cannot happen): the loop
            // drops it, braking dark.
            self.stop_galvo(out);
        }
        self.next_seq = self.next_seq.wrapping_add(1);
        let seq = self.next_seq;
        let start = Cursor { pos: 0, index: 0 };
        let piece = strokes
            .then(|| self.gcode_galvo_piece(from, start, StrokeCm::MAX_SEGMENTS, false))
            .flatten();
        let request = match (piece, lit) {
            (Some(piece), _) => {
                self.gcode.galvo = GalvoStroke {
                    seq: Some(seq),
                    cover: piece.cover,
                    ..GalvoStroke::default()
                };
                self.gcode_galvo_stroke_request(seq, piece)
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

    fn gcode_galvo_stroke_request(&self, seq: u32, piece: Piece) -> GalvoRequest {
        GalvoRequest::Path {
            seq,
            path: Figure::Stroke(piece.stroke),
            mark_speed_mm_s: Some((self.gcode_galvo_feed_mm_min(piece.feed) / 60.0) as f32),
        }
    }

    /// The block at `pos` (0: the block in flight), its steps on the galvo.
    fn gcode_galvo_block(&self, pos: usize) -> Option<(Block, u32)> {
        let motion = &self.gcode.motion;
        let c = motion.current?;
        if pos == 0 {
            return Some((c.block, c.count));
        }
        let block = *motion.queue.get(pos - 1)?;
        let steps = match block {
            Block::Arc { arc, .. } => {
                arc.segment_count(self.gcode.values.arc_tolerance_mm, MAX_ARC_CHORDS)
            }
            _ => 1,
        };
        Some((block, steps))
    }

    /// Where the piece after one starting at `start` with `cover` starts.
    fn gcode_galvo_after(&self, start: Cursor, cover: Cover) -> Cursor {
        let count = self.gcode_galvo_block(start.pos).map_or(0, |(_, n)| n);
        if cover.joined == 0 && cover.last_index < count {
            Cursor {
                pos: start.pos,
                index: cover.last_index + 1,
            }
        } else {
            Cursor {
                pos: start.pos + usize::from(cover.joined) + 1,
                index: 1,
            }
        }
    }

    /// The piece from `from` (where the piece before it ends) at `start`
    /// (index 0: the block in flight's current step) through whole lit
    /// blocks queued after it, up to `max_lines`: `None` when its first
    /// block is not a lit feed move (the block in flight: not a feed move).
    fn gcode_galvo_piece(
        &self,
        from: PointMm,
        start: Cursor,
        max_lines: usize,
        continues: bool,
    ) -> Option<Piece> {
        let (block, count) = self.gcode_galvo_block(start.pos)?;
        let index = match start.index {
            0 => self.gcode.motion.current?.index,
            index => index,
        };
        let mut feed = feed_of(&block)?;
        if start.pos > 0 && !self.lights(&block) {
            return None;
        }
        let from_cm = cm(from);
        let mut stroke = if continues {
            StrokeCm::continuing(from_cm)?
        } else {
            StrokeCm::new(from_cm)?
        };
        let mut cover = Cover {
            last_index: count,
            joined: 0,
            end: block_point(&block, 1.0),
        };
        let tolerance = self.gcode.values.arc_tolerance_mm;
        if index > 1 || !push_block(&mut stroke, &block, tolerance, max_lines) {
            // Part of the block was drawn already (or it does not fit):
            // its steps (an arc's chords) from here, up to the room.
            cover.last_index = index.saturating_sub(1);
            for k in index..=count {
                let p = point_at(&block, k, count);
                if stroke.segments() >= max_lines || !stroke.line_to(cm(p)) {
                    break;
                }
                (cover.last_index, cover.end) = (k, p);
            }
            if cover.last_index < count {
                return (stroke.segments() > 0).then_some(Piece {
                    stroke,
                    feed,
                    cover,
                });
            }
        }
        for block in self.gcode.motion.queue.iter().skip(start.pos) {
            let Some(block_feed) = feed_of(block).filter(|_| self.lights(block)) else {
                break;
            };
            if !push_block(&mut stroke, block, tolerance, max_lines) {
                break;
            }
            feed = feed.min(block_feed);
            cover.joined += 1;
            cover.end = block_point(block, 1.0);
        }
        Some(Piece {
            stroke,
            feed,
            cover,
        })
    }

    /// The galvo finished request `seq`: when it was the stroke in
    /// flight, the block in flight moves to the stroke's last step, and
    /// the blocks joined to it leave the queue (the last one becomes the
    /// block in flight, at its end); the next piece sent ahead is in
    /// flight from the next step. The caller then finishes the step.
    pub(super) fn gcode_galvo_stroke_done(&mut self, seq: u32, out: &mut dyn ActionSink) {
        let record = core::mem::take(&mut self.gcode.galvo);
        if record.seq != Some(seq) {
            return;
        }
        let [first, second] = record.ahead;
        self.gcode.galvo.adopt = first;
        self.gcode.galvo.ahead = [second, None];
        let motion = &mut self.gcode.motion;
        let Some(c) = motion.current.as_mut() else {
            return;
        };
        c.index = record.cover.last_index;
        for _ in 0..record.cover.joined {
            if let Some(block) = motion.queue.pop_front() {
                (c.block, c.index, c.count) = (block, 1, 1);
            }
        }
        if record.cover.joined > 0 {
            self.grbl_take_owed(out);
        }
    }
}

/// Adds feed move `block` (from where the stroke ends) to `stroke`: a
/// line, or an arc as its chords within `arc_tolerance_mm` (`$12`);
/// `false` (the stroke as it was) when it does not fit in `max_lines`.
fn push_block(
    stroke: &mut StrokeCm,
    block: &Block,
    arc_tolerance_mm: f64,
    max_lines: usize,
) -> bool {
    let room = max_lines
        .saturating_sub(stroke.segments())
        .min(stroke.room());
    match *block {
        Block::Line { to, .. } => room > 0 && stroke.line_to(cm(to)),
        Block::Arc { arc, .. } => {
            let chords = arc.segment_count(arc_tolerance_mm, MAX_ARC_CHORDS);
            chords as usize <= room
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

mod ahead;
mod hold;
#[cfg(test)]
mod tests;
