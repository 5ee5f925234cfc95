//! G-code on the stepper pan/tilt (`target stepper`): each block goes to
//! the stepper task as a move along its board line or arc (G0 as joint
//! travel), cut there within the stepper's line tolerance and planned by
//! its look-ahead planner. A block is handed on as soon as the stepper
//! has taken the one before ([`StepperEvent::Taken`]), so the planner
//! joins them at speed; the block before a change of the laser (dark ↔
//! lit), a dwell, a pause or the end waits for rest, so the laser switches
//! where the spot is. A feed hold decelerates along the path at the
//! limit (laser dark at once); `~` goes on from the point it stopped at:
//! the rest of the block it stopped in, then the queue.

use heapless::Deque;
use kinematics_core::Rotation;
use kinematics_core::frames::BoardPoint;

use super::gcode_motion::{Hold, cm};
use super::gcode_stream::planned_length;
use super::machine::{Action, ActionSink, Core};
use crate::domain::PointCm;
use crate::grbl::{Block, PointMm};
use crate::stepper::{MoveShape, StepperEvent, StepperRequest};

/// Moves the stepper may hold at once: its planner's pieces, the piece
/// being cut and the move waiting behind it.
const HANDED: usize = 18;

/// A move handed to the stepper: its end, shape and feed.
#[derive(Debug, Clone, Copy)]
struct Handed {
    point: BoardPoint,
    shape: MoveShape,
    feed_mm_s: Option<f64>,
}

/// What the stepper has of the G-code job.
#[derive(Debug, Clone, Default)]
pub(super) struct StepperJob {
    /// The last move handed over and not yet at rest.
    inflight: Option<u32>,
    /// The moves handed over since the stepper was last at rest (oldest
    /// first; the oldest dropped beyond [`HANDED`]), and where the oldest
    /// starts: a hold's rest point is on one of them.
    handed: Deque<Handed, HANDED>,
    start: Option<BoardPoint>,
    /// Moves still to send again after a hold (the tail of `handed`), and
    /// the request whose `Taken` sends the next.
    resend: usize,
    resend_seq: Option<u32>,
    /// The laser of the blocks handed over.
    lit: bool,
    /// The current block waits for rest before it is handed over.
    waiting: bool,
    /// Where a hold came to rest (the resume starts there).
    stopped_at: Option<BoardPoint>,
}

/// The stepper move of a motion block: end point (cm) and shape.
fn stepper_move(block: &Block) -> Option<(BoardPoint, MoveShape)> {
    let board = |p: PointMm| {
        let p = cm(p);
        BoardPoint::new(p.x_cm, p.y_cm)
    };
    Some(match *block {
        Block::Rapid { to, .. } => (board(to), MoveShape::Travel),
        Block::Line { to, .. } | Block::Jog { to, .. } => (board(to), MoveShape::Line),
        Block::Arc { arc, .. } => {
            let rotation = if arc.sweep_rad < 0.0 {
                Rotation::Cw
            } else {
                Rotation::Ccw
            };
            let centre = board(arc.centre);
            (board(arc.to), MoveShape::Arc { centre, rotation })
        }
        _ => return None,
    })
}

/// Whether `p` lies on the move from `from` to `to` short of its end:
/// within 0.05 mm of a line or an arc (a joint-space travel within 2 mm
/// of its chord).
fn short_of_end_on(from: BoardPoint, to: &Handed, p: BoardPoint) -> bool {
    let d = |a: BoardPoint, b: BoardPoint| 10.0 * libm::hypot(a.x_cm - b.x_cm, a.y_cm - b.y_cm);
    let (end, tol_mm) = match to.shape {
        MoveShape::Travel => (to.point, 2.0),
        _ => (to.point, 0.05),
    };
    if d(p, end) <= 0.05 {
        return false;
    }
    match to.shape {
        MoveShape::Arc { centre, .. } => libm::fabs(d(p, centre) - d(from, centre)) <= tol_mm,
        _ => d(from, p) + d(p, end) - d(from, end) <= tol_mm,
    }
}

impl Core {
    /// Hands the current block to the stepper (or waits for rest first).
    #[inline(never)]
    pub(super) fn gcode_stepper_send(&mut self, out: &mut dyn ActionSink) {
        let Some(current) = self.gcode.motion.current else {
            return;
        };
        let lit = self.lights(&current.block) && self.gcode.motion.hold == Hold::None;
        let job = &mut self.gcode.motion.stepper;
        if job.inflight.is_some() && (lit != job.lit || job.stopped_at.is_some()) {
            job.waiting = true;
            return;
        }
        job.waiting = false;
        let Some((point, shape)) = stepper_move(&current.block) else {
            return;
        };
        let feed_mm_s = self.stepper_feed(&current.block);
        let job = &mut self.gcode.motion.stepper;
        let handed = Handed {
            point,
            shape,
            feed_mm_s,
        };
        if let Some(at) = job.stopped_at.take() {
            // A resume: from where the hold stopped, along what it had.
            self.stepper_request(at, MoveShape::Travel, None, out);
            return self.stepper_resend(out);
        }
        if job.handed.is_full() {
            job.start = job.handed.pop_front().map(|h| h.point);
        }
        let _ = job.handed.push_back(handed);
        let seq = self.stepper_request(point, shape, feed_mm_s, out);
        self.stepper_handed(seq, lit);
    }

    /// The current block was handed over as move `seq`.
    #[inline(never)]
    fn stepper_handed(&mut self, seq: u32, lit: bool) {
        let motion = &mut self.gcode.motion;
        if let Some(c) = motion.current.as_mut() {
            c.stepper_seq = Some(seq);
        }
        motion.stepper.lit = lit;
        motion.gimbal_lit = lit && motion.arrived && motion.hold == Hold::None;
    }

    /// Sends the next move to send again after a hold (the last one is
    /// the current block's).
    #[inline(never)]
    fn stepper_resend(&mut self, out: &mut dyn ActionSink) {
        let job = &mut self.gcode.motion.stepper;
        let total = job.handed.len();
        let Some(h) = job
            .handed
            .iter()
            .nth(total - job.resend.min(total))
            .copied()
        else {
            return;
        };
        job.resend -= 1;
        let last = job.resend == 0;
        let lit = job.lit;
        let seq = self.stepper_request(h.point, h.shape, h.feed_mm_s, out);
        self.gcode.motion.stepper.resend_seq = (!last).then_some(seq);
        if last {
            self.stepper_handed(seq, lit);
        } else {
            let motion = &mut self.gcode.motion;
            motion.gimbal_lit = lit && motion.hold == Hold::None;
        }
    }

    /// A hold came to rest at `at`: the moves from the one it stopped in
    /// on are kept for the resume (that one from `at`).
    #[inline(never)]
    fn stepper_held_at(&mut self, at: BoardPoint) {
        let job = &mut self.gcode.motion.stepper;
        let mut from = job.start.unwrap_or(at);
        let mut keep = job.handed.len();
        for (i, h) in job.handed.iter().enumerate() {
            if short_of_end_on(from, h, at) {
                keep = job.handed.len() - i;
                break;
            }
            from = h.point;
        }
        // Stopped past every move (at the last end): the last one again,
        // an empty move from there.
        job.resend = keep.max(1);
        job.stopped_at = Some(at);
    }

    /// The spot speed of a feed move with the feed override, mm/s
    /// (`None`: G0, at the axes' limit).
    #[inline(never)]
    fn stepper_feed(&self, block: &Block) -> Option<f64> {
        let feed_mm_min = match *block {
            Block::Line { feed_mm_min, .. }
            | Block::Arc { feed_mm_min, .. }
            | Block::Jog { feed_mm_min, .. } => feed_mm_min,
            _ => return None,
        };
        Some(feed_mm_min * f64::from(self.gcode.overrides.feed) / 6000.0)
    }

    /// One move request to the stepper; returns its number.
    #[inline(never)]
    fn stepper_request(
        &mut self,
        point: BoardPoint,
        shape: MoveShape,
        feed_mm_s: Option<f64>,
        out: &mut dyn ActionSink,
    ) -> u32 {
        self.next_seq = self.next_seq.wrapping_add(1);
        let seq = self.next_seq;
        out.act(Action::Stepper(StepperRequest::MoveTo {
            seq,
            point,
            shape,
            feed_mm_s,
        }));
        self.gcode.motion.stepper.inflight = Some(seq);
        seq
    }

    /// Whether the block after the current one joins it at speed: a
    /// motion with the same laser, no hold.
    #[inline(never)]
    fn stepper_joins_next(&self) -> bool {
        let motion = &self.gcode.motion;
        let same_laser = |b: &Block| self.lights(b) == motion.stepper.lit;
        motion.hold == Hold::None
            && motion
                .queue
                .front()
                .is_some_and(|b| planned_length(b).is_some() && same_laser(b))
    }

    /// The G-code side of a stepper report: `true` when it was the job's.
    #[inline(never)]
    pub(super) fn gcode_stepper_event(
        &mut self,
        event: &StepperEvent,
        out: &mut dyn ActionSink,
    ) -> bool {
        let current = self.gcode.motion.current;
        let ours = |seq: u32| current.is_some_and(|c| c.stepper_seq == Some(seq));
        let joins = self.stepper_joins_next();
        let motion = &mut self.gcode.motion;
        match *event {
            StepperEvent::Taken { seq } if motion.stepper.resend_seq == Some(seq) => {
                motion.stepper.resend_seq = None;
                self.stepper_resend(out);
                true
            }
            StepperEvent::Taken { seq } if ours(seq) && joins => {
                self.gcode_stepper_done(out);
                true
            }
            StepperEvent::Arrived { seq, .. } if motion.stepper.inflight == Some(seq) => {
                motion.stepper.inflight = None;
                motion.stepper.handed.clear();
                motion.stepper.start = Some(motion.stepper_point());
                motion.arrived = true;
                if ours(seq) {
                    self.gcode_stepper_done(out);
                } else if motion.stepper.waiting {
                    self.gcode_stepper_send(out);
                }
                true
            }
            StepperEvent::Stopped { steps } => {
                let config = self.stepper_config();
                let at = config
                    .joints_of(steps)
                    .and_then(|j| config.gimbal.fk(j).ok());
                let motion = &mut self.gcode.motion;
                motion.stepper.inflight = None;
                if let Some(p) = at {
                    motion.position = PointMm {
                        x_mm: p.x_cm * 10.0,
                        y_mm: p.y_cm * 10.0,
                    };
                }
                let held = motion.hold == Hold::Stopping;
                if held {
                    motion.hold = Hold::Held;
                    if let Some(c) = motion.current.as_mut() {
                        c.stepper_seq = None;
                    }
                }
                if let Some(p) = at.filter(|_| held) {
                    self.stepper_held_at(p);
                }
                self.grbl_sync_position();
                false
            }
            _ => false,
        }
    }

    /// The current block is done on the stepper's side.
    #[inline(never)]
    fn gcode_stepper_done(&mut self, out: &mut dyn ActionSink) {
        if let Some(c) = self.gcode.motion.current.as_mut() {
            c.stepper_seq = None;
        }
        self.gcode_step_done(out);
    }

    /// `!` on the stepper: decelerate along the path, dark at once.
    /// `false` when nothing moves there.
    #[inline(never)]
    pub(super) fn gcode_stepper_hold(&mut self, out: &mut dyn ActionSink) -> bool {
        let motion = &mut self.gcode.motion;
        if !self.actuator.uses_stepper() || motion.stepper.inflight.is_none() {
            return false;
        }
        motion.gimbal_lit = false;
        motion.hold = Hold::Stopping;
        out.act(Action::Stepper(StepperRequest::Stop));
        true
    }

    /// Whether the stepper reaches board point `p` within its soft limits.
    #[inline(never)]
    pub(super) fn stepper_reaches(&self, p: PointCm) -> bool {
        let config = self.stepper_config();
        config
            .gimbal
            .ik(BoardPoint::new(p.x_cm, p.y_cm))
            .is_ok_and(|j| config.steps_of(j).is_ok())
    }
}

impl StepperJob {
    /// Forgets the job (a stop, a reset); in place (the ring is large
    /// for the sequencer's stack).
    #[inline(never)]
    pub(super) fn clear(&mut self) {
        self.inflight = None;
        self.handed.clear();
        self.start = None;
        self.resend = 0;
        self.resend_seq = None;
        self.lit = false;
        self.waiting = false;
        self.stopped_at = None;
    }
}

impl super::gcode_motion::Motion {
    /// Where the G-code spot is, board cm.
    #[inline(never)]
    fn stepper_point(&self) -> BoardPoint {
        let p = cm(self.position);
        BoardPoint::new(p.x_cm, p.y_cm)
    }
}
