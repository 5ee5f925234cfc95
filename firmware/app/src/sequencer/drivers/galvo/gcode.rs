//! The galvo driver's G-code stage: lit blocks joined into strokes, pieces sent ahead.

use crate::domain::{Figure, StrokeCm};
#[cfg(doc)]
use crate::galvo::GalvoEvent;
use crate::galvo::GalvoRequest;
use crate::grbl::{Block, PointMm};
use crate::sequencer::drivers::galvo::{Cover, Cursor, GalvoStroke, MAX_ARC_CHORDS, Piece};
use crate::sequencer::drivers::stage::Stage;
use crate::sequencer::gcode::queue::{block_point, cm, point_at};
use crate::sequencer::io::ActionSink;

impl GalvoStroke {
    /// The galvo's request for the G-code step from `from` to `to` at
    /// `feed` (mm/min), `lit` or dark, with its number; `None` when it
    /// could not be sent (the loop does not keep up:
    /// [`Stage::galvo_stalled`]).
    pub(in crate::sequencer) fn send_step(
        &mut self,
        st: &mut Stage,
        from: PointMm,
        to: PointMm,
        feed: Option<f64>,
        lit: bool,
        out: &mut dyn ActionSink,
    ) -> Option<u32> {
        let strokes = lit && !st.drivers.lockstep();
        if let Some(next) = self.adopt.take() {
            if strokes && let Some(seq) = self.adopt(st, from, next) {
                return Some(seq);
            }
            // Not the step it was sent for (cannot happen): the loop
            // drops it, braking dark.
            st.stop_galvo(out);
        }
        let seq = st.take_seq();
        let start = Cursor { pos: 0, index: 0 };
        let piece = strokes
            .then(|| piece(st, from, start, StrokeCm::MAX_SEGMENTS, false))
            .flatten();
        let request = match (piece, lit) {
            (Some(piece), _) => {
                *self = GalvoStroke {
                    seq: Some(seq),
                    cover: piece.cover,
                    ..GalvoStroke::default()
                };
                stroke_request(st, seq, piece)
            }
            (None, true) => GalvoRequest::Path {
                seq,
                path: Figure::Line {
                    from: cm(from),
                    to: cm(to),
                },
                mark_speed_mm_s: feed.map(|f| (feed_mm_min(st, f) / 60.0) as f32),
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
        st.send_galvo(request, out).then_some(seq)
    }

    /// The galvo finished request `seq`: when it was the stroke in
    /// flight, the block in flight moves to the stroke's last step, and
    /// the blocks joined to it leave the queue (the last one becomes the
    /// block in flight, at its end); the next piece sent ahead is in
    /// flight from the next step. `true` when blocks left the queue (a
    /// line waiting for room is then queued). The caller then finishes
    /// the step.
    pub(in crate::sequencer) fn done(&mut self, st: &mut Stage, seq: u32) -> bool {
        let record = core::mem::take(self);
        if record.seq != Some(seq) {
            return false;
        }
        let [first, second] = record.ahead;
        self.adopt = first;
        self.ahead = [second, None];
        let motion = &mut st.gcode.motion;
        let Some(c) = motion.current.as_mut() else {
            return false;
        };
        c.index = record.cover.last_index;
        for _ in 0..record.cover.joined {
            if let Some(block) = motion.queue.pop_front() {
                (c.block, c.index, c.count) = (block, 1, 1);
            }
        }
        record.cover.joined > 0
    }
}

/// The galvo request marking `piece` as stroke `seq`.
pub(super) fn stroke_request(st: &Stage, seq: u32, piece: Piece) -> GalvoRequest {
    GalvoRequest::Path {
        seq,
        path: Figure::Stroke(piece.stroke),
        mark_speed_mm_s: Some((feed_mm_min(st, piece.feed) / 60.0) as f32),
    }
}

/// The block at `pos` (0: the block in flight), its steps on the galvo.
pub(super) fn block_at(st: &Stage, pos: usize) -> Option<(Block, u32)> {
    let motion = &st.gcode.motion;
    let c = motion.current?;
    if pos == 0 {
        return Some((c.block, c.count));
    }
    let block = *motion.queue.get(pos - 1)?;
    let steps = match block {
        Block::Arc { arc, .. } => {
            arc.segment_count(st.gcode.values.arc_tolerance_mm, MAX_ARC_CHORDS)
        }
        _ => 1,
    };
    Some((block, steps))
}

/// Where the piece after one starting at `start` with `cover` starts.
pub(super) fn after(st: &Stage, start: Cursor, cover: Cover) -> Cursor {
    let count = block_at(st, start.pos).map_or(0, |(_, n)| n);
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
pub(super) fn piece(
    st: &Stage,
    from: PointMm,
    start: Cursor,
    max_lines: usize,
    continues: bool,
) -> Option<Piece> {
    let (block, count) = block_at(st, start.pos)?;
    let index = match start.index {
        0 => st.gcode.motion.current?.index,
        index => index,
    };
    let mut feed = feed_of(&block)?;
    if start.pos > 0 && !st.lights(&block) {
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
    let tolerance = st.gcode.values.arc_tolerance_mm;
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
    for block in st.gcode.motion.queue.iter().skip(start.pos) {
        let Some(block_feed) = feed_of(block).filter(|_| st.lights(block)) else {
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

/// The galvo's marking feed for programmed feed `feed_mm_min`: the feed
/// override applied, capped by the galvo's marking speed
/// (`galvo.mark_speed_mm_s`), mm/min.
fn feed_mm_min(st: &Stage, feed_mm_min: f64) -> f64 {
    let feed = st.gcode.overrides.feed_mm_min(feed_mm_min);
    feed.min(st.settings.galvo.mark_speed_mm_s * 60.0)
}
