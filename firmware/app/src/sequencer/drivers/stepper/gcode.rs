//! The stepper driver's G-code stage: blocks handed over whole to its task.

use crate::domain::units::mm_from_cm;
use crate::grbl::{Block, Laser, PointMm};
use crate::sequencer::drivers::stage::Stage;
use crate::sequencer::drivers::stepper::{StepperJob, config};
use crate::sequencer::gcode::queue::{Hold, cm, planned_length};
use crate::sequencer::io::{Action, ActionSink};
use crate::settings::Settings;
use crate::stepper::{MoveShape, StepperEvent, StepperRequest};
use kinematics_core::Rotation;
use kinematics_core::frames::BoardPoint;

/// What a stepper report means to the G-code session
/// ([`StepperJob::event`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::sequencer) enum StepperReport {
    /// Not the job's.
    Other,
    /// The job's, nothing more to do.
    Handled,
    /// The current block is done on the stepper's side.
    BlockDone,
    /// The stepper refused the move handed over (beyond its soft limits).
    Refused,
    /// The stepper came to rest (the session syncs its position).
    AtRest,
}

impl StepperJob {
    /// Hands the current block to the stepper (or waits for rest first).
    #[inline(never)]
    pub(in crate::sequencer) fn send(&mut self, st: &mut Stage, out: &mut dyn ActionSink) {
        let Some(current) = st.gcode.motion.current else {
            return;
        };
        let lit = st.lights(&current.block) && st.gcode.motion.hold == Hold::None;
        let laser = block_laser(&current.block);
        if self.inflight.is_some() && (lit != self.lit || (lit && laser != self.laser)) {
            self.waiting = true;
            return;
        }
        self.waiting = false;
        if core::mem::take(&mut self.held) {
            // A resume: the stepper goes on with the moves it had, from
            // where the hold stopped.
            self.inflight = current.stepper_seq;
            out.act(Action::Stepper(StepperRequest::Resume));
            st.gcode.motion.gimbal_lit = lit;
            return;
        }
        let Some((point, shape)) = stepper_move(&current.block) else {
            return;
        };
        self.send_override(st.gcode.overrides.feed, st.drivers.hands_over_blocks(), out);
        junction(st.settings, &mut st.gcode.stepper_junction_deg, true, out);
        let feed_mm_s = stepper_feed(&current.block);
        let seq = self.request(st, point, shape, feed_mm_s, out);
        let motion = &mut st.gcode.motion;
        if let Some(c) = motion.current.as_mut() {
            c.stepper_seq = Some(seq);
        }
        self.lit = lit;
        self.laser = laser;
        // Unlike a servo's, the stepper's position is known from the
        // start (its counted steps): the first move is cut from there.
        motion.gimbal_lit = lit;
    }

    /// Tells the stepper task the feed override `percent` when it changed
    /// (`stepping`: the stepper draws; it applies it on the fly, to the
    /// move being cut too).
    #[inline(never)]
    pub(in crate::sequencer) fn send_override(
        &mut self,
        percent: u8,
        stepping: bool,
        out: &mut dyn ActionSink,
    ) {
        if stepping && self.feed_percent != Some(percent) {
            self.feed_percent = Some(percent);
            out.act(Action::Stepper(StepperRequest::FeedOverride { percent }));
        }
    }

    /// One move request to the stepper; returns its number.
    #[inline(never)]
    fn request(
        &mut self,
        st: &mut Stage,
        point: BoardPoint,
        shape: MoveShape,
        feed_mm_s: Option<f64>,
        out: &mut dyn ActionSink,
    ) -> u32 {
        let seq = st.take_seq();
        out.act(Action::Stepper(StepperRequest::MoveTo {
            seq,
            point,
            shape,
            feed_mm_s,
        }));
        self.inflight = Some(seq);
        seq
    }

    /// Whether the block after the current one joins it at speed: a
    /// motion with the same laser (dark, or lit with the same M3/M4 and
    /// S), no hold.
    #[inline(never)]
    fn joins_next(&self, st: &Stage) -> bool {
        let motion = &st.gcode.motion;
        let same_laser =
            |b: &Block| st.lights(b) == self.lit && (!self.lit || block_laser(b) == self.laser);
        motion.hold == Hold::None
            && motion
                .queue
                .front()
                .is_some_and(|b| planned_length(b).is_some() && same_laser(b))
    }

    /// The G-code side of a stepper report: what it means to the session.
    #[inline(never)]
    pub(in crate::sequencer) fn event(
        &mut self,
        st: &mut Stage,
        event: &StepperEvent,
        out: &mut dyn ActionSink,
    ) -> StepperReport {
        let current = st.gcode.motion.current;
        let ours = |seq: u32| current.is_some_and(|c| c.stepper_seq == Some(seq));
        let joins = self.joins_next(st);
        match *event {
            StepperEvent::Taken { seq } if ours(seq) && joins => StepperReport::BlockDone,
            StepperEvent::Arrived { seq, .. } if self.inflight == Some(seq) => {
                self.inflight = None;
                st.gcode.motion.arrived = true;
                if ours(seq) {
                    return StepperReport::BlockDone;
                } else if self.waiting {
                    self.send(st, out);
                }
                StepperReport::Handled
            }
            StepperEvent::Refused { seq, .. } if self.inflight == Some(seq) => {
                StepperReport::Refused
            }
            StepperEvent::Stopped { steps } => {
                let braked = core::mem::take(&mut self.braking);
                if !braked && !st.gcode.motion.is_idle() {
                    // The rest of a stop from before the job (`target
                    // stepper` typed ahead of it): its moves run on.
                    return StepperReport::Other;
                }
                self.at(st, steps);
                let motion = &mut st.gcode.motion;
                self.held |= braked;
                match motion.hold {
                    Hold::Stopping if braked => motion.hold = Hold::Held,
                    // `~` came while it braked: it goes on now it is at
                    // rest (grbl resumes a hold once it is complete).
                    Hold::None if braked => self.send(st, out),
                    _ => {}
                }
                StepperReport::AtRest
            }

            _ => StepperReport::Other,
        }
    }

    /// The stepper is at rest at `steps`: MPos from the counted steps.
    #[inline(never)]
    pub(in crate::sequencer) fn at(&mut self, st: &mut Stage, steps: [i32; 2]) {
        let config = config(st.settings);
        let at = config
            .joints_of(steps)
            .and_then(|j| config.gimbal.fk(j).ok());
        let motion = &mut st.gcode.motion;
        self.inflight = None;
        if let Some(p) = at {
            motion.position = PointMm {
                x_mm: mm_from_cm(p.x_cm),
                y_mm: mm_from_cm(p.y_cm),
            };
        }
    }

    /// `!` on the stepper: decelerate along the path, dark at once.
    /// `false` when nothing moves there.
    #[inline(never)]
    pub(in crate::sequencer) fn hold(&mut self, st: &mut Stage, out: &mut dyn ActionSink) -> bool {
        let stepping = st.drivers.hands_over_blocks();
        let motion = &mut st.gcode.motion;
        if !stepping || self.inflight.is_none() {
            return false;
        }
        motion.gimbal_lit = false;
        motion.hold = Hold::Stopping;
        self.braking = true;
        out.act(Action::Stepper(StepperRequest::Hold));
        true
    }

    /// Whether the stepper runs a move of the job.
    pub(in crate::sequencer) fn is_moving(&self) -> bool {
        self.inflight.is_some()
    }
}

/// The stepper plans with the junction deviation of `gcode` (grbl's
/// `$11`, mm at the board, as joint degrees at its centre) or of the
/// product (`stepper.junction_deg`); told when it changes (`current`:
/// what it was told last, joint degrees; `None`: the product's).
pub(in crate::sequencer) fn junction(
    settings: &Settings,
    current: &mut Option<f64>,
    gcode: bool,
    out: &mut dyn ActionSink,
) {
    let want =
        gcode.then(|| (settings.gcode_junction_mm / mm_from_cm(settings.oq_cm)).to_degrees());
    if want != *current {
        *current = want;
        let deviation_deg = want.unwrap_or(settings.stepper.junction_deviation_deg);
        out.act(Action::Stepper(StepperRequest::Junction { deviation_deg }));
    }
}

/// The programmed spot speed of a feed move, mm/s (`None`: G0, at the
/// axes' limit); the stepper task applies the feed override.
fn stepper_feed(block: &Block) -> Option<f64> {
    match *block {
        Block::Line { feed_mm_min, .. }
        | Block::Arc { feed_mm_min, .. }
        | Block::Jog { feed_mm_min, .. } => Some(feed_mm_min / 60.0),
        _ => None,
    }
}

/// The laser setting of a feed block (default for others).
fn block_laser(block: &Block) -> Laser {
    match *block {
        Block::Line { laser, .. } | Block::Arc { laser, .. } => laser,
        _ => Laser::default(),
    }
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
