//! A G-code feed hold on the stepper: the moves queued since the axes were
//! last at rest are remembered; after a hold has come to rest, a resume
//! queues them again from the rest point — the rest of the move it stopped
//! in, then the ones after it, one at a time as the cutting takes them —
//! under their own request numbers.

use kinematics_core::frames::BoardPoint;

use super::super::link::messages::{MoveShape, StepperRefusal};
use super::StepperMotion;
use super::history::Remembered;

/// Whether `p` lies on the move from `from` to `to` short of its end:
/// within 0.05 mm of a line or an arc (a joint-space travel within 2 mm
/// of its chord).
fn short_of_end_on(from: BoardPoint, to: &Remembered, p: BoardPoint) -> bool {
    let d = |a: BoardPoint, b: BoardPoint| {
        crate::domain::units::mm_from_cm(kinematics_core::numeric::hypot(
            a.x_cm - b.x_cm,
            a.y_cm - b.y_cm,
        ))
    };
    let tol_mm = if to.shape == MoveShape::Travel {
        2.0
    } else {
        0.05
    };
    if d(p, to.point) <= 0.05 {
        return false;
    }
    match to.shape {
        MoveShape::Arc { centre, .. } => libm::fabs(d(p, centre) - d(from, centre)) <= tol_mm,
        _ => d(from, p) + d(p, to.point) - d(from, to.point) <= tol_mm,
    }
}

impl StepperMotion {
    /// After a hold came to rest at step position `steps`: queues again,
    /// from there, the moves it had (the one it stopped in first).
    ///
    /// Errors: [`StepperRefusal::Unreachable`] (the rest point has no
    /// board point; nothing queued).
    pub fn resume(&mut self, steps: [i32; 2]) -> Result<(), StepperRefusal> {
        let at = self
            .board_point_of(steps)
            .ok_or(StepperRefusal::Unreachable)?;
        let h = &mut self.history;
        let mut from = h.start.unwrap_or(at);
        let mut again = h.moves.len();
        for (i, m) in h.moves.iter().enumerate() {
            if short_of_end_on(from, m, at) {
                again = h.moves.len() - i;
                break;
            }
            from = m.point;
        }
        // Stopped past every move: the last one again (empty from there).
        h.again = again.max(1);
        self.last_point = Some(at);
        self.queue_again();
        Ok(())
    }

    /// Queues the next moves to queue again while the cutting takes them.
    pub(super) fn queue_again(&mut self) {
        while self.history.again > 0 && self.next.is_none() {
            let total = self.history.moves.len();
            let index = total.saturating_sub(self.history.again);
            let Some(m) = self.history.moves.iter().nth(index).copied() else {
                self.history.again = 0;
                return;
            };
            self.history.again -= 1;
            match self.queue(m.seq, m.point, m.shape, m.feed_mm_s) {
                Ok(true) => self.started = Some(m.seq),
                Ok(false) => {}
                Err(_) => self.history.again = 0,
            }
        }
    }
}
