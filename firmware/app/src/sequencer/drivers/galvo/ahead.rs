//! Pieces sent ahead of the stroke in flight on the galvo (see
//! [`super`]): sending them as far as lit blocks are queued, and the
//! next one taking over when the piece in flight is done.

use crate::grbl::PointMm;
use crate::sequencer::drivers::galvo::{AHEAD, AHEAD_LINES, Cover, Cursor};
use crate::sequencer::gcode::queue::Hold;
use crate::sequencer::machine::{ActionSink, Core};

/// A piece sent ahead of the one in flight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::sequencer) struct Ahead {
    pub(in crate::sequencer) seq: u32,
    pub(super) start: Cursor,
    pub(super) cover: Cover,
    pub(in crate::sequencer) lines: u8,
}

impl Core {
    /// The piece `next`, sent ahead, becomes the one in flight: it starts
    /// at the block in flight now. Its number, or `None` when it does not
    /// start here.
    pub(in crate::sequencer) fn gcode_galvo_adopt(
        &mut self,
        from: PointMm,
        next: Ahead,
    ) -> Option<u32> {
        let start = Cursor { pos: 0, index: 0 };
        let piece = self.gcode_galvo_piece(from, start, usize::from(next.lines), true)?;
        if piece.stroke.segments() != usize::from(next.lines) || piece.cover != next.cover {
            return None;
        }
        let record = &mut self.jobs.galvo;
        record.seq = Some(next.seq);
        record.cover = piece.cover;
        for a in record.ahead.iter_mut().flatten() {
            a.start.pos = a.start.pos.saturating_sub(next.start.pos);
        }
        Some(next.seq)
    }

    /// Sends the pieces that continue the stroke in flight, as far as
    /// lit blocks are queued, up to [`AHEAD`] pieces ahead (after a step
    /// is sent, and when blocks are queued).
    pub(in crate::sequencer) fn gcode_galvo_send_ahead(&mut self, out: &mut dyn ActionSink) {
        let motion = &self.gcode.motion;
        let in_flight = motion
            .current
            .is_some_and(|c| c.galvo_seq.is_some() && c.galvo_seq == self.jobs.galvo.seq);
        if !in_flight || motion.hold != Hold::None || self.drivers().lockstep() {
            return;
        }
        loop {
            let record = self.jobs.galvo;
            let sent = record.ahead.iter().flatten().count();
            // One request slot stays free (for the stroke after).
            let room = self.inputs.galvo_room.is_some_and(|room| room > 1);
            if !room || sent >= AHEAD {
                return;
            };
            let last = record.ahead.iter().flatten().last();
            let (start, cover) = match last {
                Some(a) => (a.start, a.cover),
                None => (Cursor { pos: 0, index: 0 }, record.cover),
            };
            let start = self.gcode_galvo_after(start, cover);
            let Some(piece) = self.gcode_galvo_piece(cover.end, start, AHEAD_LINES, true) else {
                return;
            };
            self.next_seq = self.next_seq.wrapping_add(1);
            let seq = self.next_seq;
            let ahead = Ahead {
                seq,
                start,
                cover: piece.cover,
                lines: piece.stroke.segments() as u8,
            };
            let request = self.gcode_galvo_stroke_request(seq, piece);
            if !self.send_galvo(request, out) {
                return;
            }
            if let Some(slot) = self.jobs.galvo.ahead.get_mut(sent) {
                *slot = Some(ahead);
            }
        }
    }

    /// After a piece's `done`: a piece sent ahead that the next step did
    /// not take over (cannot happen) is dropped from the galvo, which
    /// brakes dark, rather than left to be marked behind the sequencer's
    /// back.
    pub(in crate::sequencer) fn gcode_galvo_drop_unadopted(&mut self, out: &mut dyn ActionSink) {
        if self.jobs.galvo.adopt.take().is_some() {
            self.stop_galvo(out);
        }
    }

    /// Whether `seq` is a piece sent ahead of the stroke in flight.
    pub(in crate::sequencer) fn gcode_galvo_ahead_is(&self, seq: u32) -> bool {
        let g = &self.jobs.galvo;
        g.ahead
            .iter()
            .chain([&g.adopt])
            .flatten()
            .any(|a| a.seq == seq)
    }
}
