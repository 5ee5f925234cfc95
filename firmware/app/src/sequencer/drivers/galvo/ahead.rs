//! Pieces sent ahead of the stroke in flight on the galvo (see
//! [`super`]): sending them as far as lit blocks are queued, and the
//! next one taking over when the piece in flight is done.

use crate::grbl::PointMm;
use crate::sequencer::drivers::galvo::gcode::{after, piece, stroke_request};
use crate::sequencer::drivers::galvo::{AHEAD, AHEAD_LINES, Ahead, Cursor, GalvoStroke};
use crate::sequencer::drivers::stage::Stage;
use crate::sequencer::gcode::queue::Hold;
use crate::sequencer::io::ActionSink;

impl GalvoStroke {
    /// The piece `next`, sent ahead, becomes the one in flight: it starts
    /// at the block in flight now. Its number, or `None` when it does not
    /// start here.
    pub(super) fn adopt(&mut self, st: &Stage, from: PointMm, next: Ahead) -> Option<u32> {
        let start = Cursor { pos: 0, index: 0 };
        let piece = piece(st, from, start, usize::from(next.lines), true)?;
        if piece.stroke.segments() != usize::from(next.lines) || piece.cover != next.cover {
            return None;
        }
        self.seq = Some(next.seq);
        self.cover = piece.cover;
        for a in self.ahead.iter_mut().flatten() {
            a.start.pos = a.start.pos.saturating_sub(next.start.pos);
        }
        Some(next.seq)
    }

    /// Sends the pieces that continue the stroke in flight, as far as
    /// lit blocks are queued, up to [`AHEAD`] pieces ahead (after a step
    /// is sent, and when blocks are queued).
    pub(in crate::sequencer) fn send_ahead(&mut self, st: &mut Stage, out: &mut dyn ActionSink) {
        let motion = &st.gcode.motion;
        let in_flight = motion
            .current
            .is_some_and(|c| c.galvo_seq.is_some() && c.galvo_seq == self.seq);
        if !in_flight || motion.hold != Hold::None || st.drivers.lockstep() {
            return;
        }
        loop {
            let record = *self;
            let sent = record.ahead.iter().flatten().count();
            // One request slot stays free (for the stroke after).
            let room = st.inputs.galvo_room.is_some_and(|room| room > 1);
            if !room || sent >= AHEAD {
                return;
            };
            let last = record.ahead.iter().flatten().last();
            let (start, cover) = match last {
                Some(a) => (a.start, a.cover),
                None => (Cursor { pos: 0, index: 0 }, record.cover),
            };
            let start = after(st, start, cover);
            let Some(piece) = piece(st, cover.end, start, AHEAD_LINES, true) else {
                return;
            };
            let seq = st.take_seq();
            let ahead = Ahead {
                seq,
                start,
                cover: piece.cover,
                lines: piece.stroke.segments() as u8,
            };
            let request = stroke_request(st, seq, piece);
            if !st.send_galvo(request, out) {
                return;
            }
            if let Some(slot) = self.ahead.get_mut(sent) {
                *slot = Some(ahead);
            }
        }
    }

    /// After a piece's `done`: a piece sent ahead that the next step did
    /// not take over (cannot happen) is dropped from the galvo, which
    /// brakes dark, rather than left to be marked behind the sequencer's
    /// back.
    pub(in crate::sequencer) fn drop_unadopted(
        &mut self,
        st: &mut Stage,
        out: &mut dyn ActionSink,
    ) {
        if self.adopt.take().is_some() {
            st.stop_galvo(out);
        }
    }

    /// Whether `seq` is a piece sent ahead of the stroke in flight.
    pub(in crate::sequencer) fn ahead_is(&self, seq: u32) -> bool {
        self.ahead
            .iter()
            .chain([&self.adopt])
            .flatten()
            .any(|a| a.seq == seq)
    }
}
