//! The moves the stepper queued since its axes were last at rest
//! ([`History`]), for a feed hold's resume (`resume.rs`).

use heapless::Deque;
use kinematics_core::frames::BoardPoint;

use super::super::link::messages::MoveShape;

/// Moves the stepper can hold at once: its planner's pieces (each move at
/// least one), the piece being cut and the move waiting behind it.
const REMEMBERED: usize = 18;

/// A move queued since the last rest: request number, end, shape, feed.
#[derive(Debug, Clone, Copy)]
pub(super) struct Remembered {
    pub(super) seq: u32,
    pub(super) point: BoardPoint,
    pub(super) shape: MoveShape,
    pub(super) feed_mm_s: Option<f64>,
}

/// The moves queued since the last rest and where the oldest starts.
#[derive(Debug, Clone, Default)]
pub(super) struct History {
    pub(super) moves: Deque<Remembered, REMEMBERED>,
    pub(super) start: Option<BoardPoint>,
    /// Moves still to queue again (the tail of `moves`).
    pub(super) again: usize,
}

impl History {
    /// Remembers a move queued (the oldest goes beyond [`REMEMBERED`]).
    pub(super) fn push(
        &mut self,
        seq: u32,
        point: BoardPoint,
        shape: MoveShape,
        feed_mm_s: Option<f64>,
    ) {
        if self.moves.is_full() {
            self.start = self.moves.pop_front().map(|m| m.point);
        }
        let _ = self.moves.push_back(Remembered {
            seq,
            point,
            shape,
            feed_mm_s,
        });
    }

    /// Whether nothing waits to be queued again.
    pub(super) fn is_done(&self) -> bool {
        self.again == 0
    }

    /// At rest at `at`: nothing to remember.
    pub(super) fn rest(&mut self, at: Option<BoardPoint>) {
        self.moves.clear();
        self.start = at;
        self.again = 0;
    }
}
