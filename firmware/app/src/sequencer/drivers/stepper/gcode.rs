//! The stepper driver's G-code stage: blocks handed over whole to its task.

use crate::domain::PointCm;
use crate::grbl::{Alarm, Block, GrblError, Laser, PointMm};
use crate::sequencer::drivers::stepper::StepperJob;
use crate::sequencer::gcode::GrblMode;
use crate::sequencer::gcode::queue::{Hold, cm, planned_length};
use crate::sequencer::machine::{Action, ActionSink, Core};
use crate::stepper::{HomingFailure, MoveShape, StepperEvent, StepperRequest};
use crate::text::reply_text;
use kinematics_core::Rotation;
use kinematics_core::frames::BoardPoint;

impl Core {
    /// Hands the current block to the stepper (or waits for rest first).
    #[inline(never)]
    pub(in crate::sequencer) fn gcode_stepper_send(&mut self, out: &mut dyn ActionSink) {
        let Some(current) = self.gcode.motion.current else {
            return;
        };
        let lit = self.lights(&current.block) && self.gcode.motion.hold == Hold::None;
        let laser = block_laser(&current.block);
        let job = &mut self.jobs.stepper;
        if job.inflight.is_some() && (lit != job.lit || (lit && laser != job.laser)) {
            job.waiting = true;
            return;
        }
        job.waiting = false;
        if core::mem::take(&mut job.held) {
            // A resume: the stepper goes on with the moves it had, from
            // where the hold stopped.
            job.inflight = current.stepper_seq;
            out.act(Action::Stepper(StepperRequest::Resume));
            self.gcode.motion.gimbal_lit = lit;
            return;
        }
        let Some((point, shape)) = stepper_move(&current.block) else {
            return;
        };
        self.gcode_stepper_override(out);
        self.stepper_junction(true, out);
        let feed_mm_s = self.stepper_feed(&current.block);
        let seq = self.stepper_request(point, shape, feed_mm_s, out);
        let motion = &mut self.gcode.motion;
        if let Some(c) = motion.current.as_mut() {
            c.stepper_seq = Some(seq);
        }
        self.jobs.stepper.lit = lit;
        self.jobs.stepper.laser = laser;
        // Unlike a servo's, the stepper's position is known from the
        // start (its counted steps): the first move is cut from there.
        motion.gimbal_lit = lit;
    }

    /// The programmed spot speed of a feed move, mm/s (`None`: G0, at
    /// the axes' limit); the stepper task applies the feed override.
    #[inline(never)]
    fn stepper_feed(&self, block: &Block) -> Option<f64> {
        match *block {
            Block::Line { feed_mm_min, .. }
            | Block::Arc { feed_mm_min, .. }
            | Block::Jog { feed_mm_min, .. } => Some(feed_mm_min / 60.0),
            _ => None,
        }
    }

    /// Tells the stepper task the feed override when it changed (it
    /// applies it on the fly, to the move being cut too).
    #[inline(never)]
    pub(in crate::sequencer) fn gcode_stepper_override(&mut self, out: &mut dyn ActionSink) {
        let percent = self.gcode.overrides.feed;
        let stepping = self.drivers().hands_over_blocks();
        let job = &mut self.jobs.stepper;
        if stepping && job.feed_percent != Some(percent) {
            job.feed_percent = Some(percent);
            out.act(Action::Stepper(StepperRequest::FeedOverride { percent }));
        }
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
        self.jobs.stepper.inflight = Some(seq);
        seq
    }

    /// Whether the block after the current one joins it at speed: a
    /// motion with the same laser (dark, or lit with the same M3/M4 and
    /// S), no hold.
    #[inline(never)]
    fn stepper_joins_next(&self) -> bool {
        let motion = &self.gcode.motion;
        let job = &self.jobs.stepper;
        let same_laser =
            |b: &Block| self.lights(b) == job.lit && (!job.lit || block_laser(b) == job.laser);
        motion.hold == Hold::None
            && motion
                .queue
                .front()
                .is_some_and(|b| planned_length(b).is_some() && same_laser(b))
    }

    /// The G-code side of a stepper report: `true` when it was the job's.
    #[inline(never)]
    pub(in crate::sequencer) fn gcode_stepper_event(
        &mut self,
        event: &StepperEvent,
        out: &mut dyn ActionSink,
    ) -> bool {
        let current = self.gcode.motion.current;
        let ours = |seq: u32| current.is_some_and(|c| c.stepper_seq == Some(seq));
        let joins = self.stepper_joins_next();
        let motion = &mut self.gcode.motion;
        match *event {
            StepperEvent::Taken { seq } if ours(seq) && joins => {
                self.gcode_stepper_done(out);
                true
            }
            StepperEvent::Arrived { seq, .. } if self.jobs.stepper.inflight == Some(seq) => {
                self.jobs.stepper.inflight = None;
                motion.arrived = true;
                if ours(seq) {
                    self.gcode_stepper_done(out);
                } else if self.jobs.stepper.waiting {
                    self.gcode_stepper_send(out);
                }
                true
            }
            StepperEvent::Refused { seq, why } if self.jobs.stepper.inflight == Some(seq) => {
                // The checks before it passed, the stepper refused it
                // (its axes beyond their soft limits): as on the galvo.
                self.notify(out, format_args!("MSG:stepper: move refused: {why:?}"));
                self.grbl_alarm(Alarm::SoftLimit, out);
                true
            }
            StepperEvent::Stopped { steps } => {
                let braked = core::mem::take(&mut self.jobs.stepper.braking);
                if !braked && !motion.is_idle() {
                    // The rest of a stop from before the job (`target
                    // stepper` typed ahead of it): its moves run on.
                    return false;
                }
                self.gcode_stepper_at(steps);
                let motion = &mut self.gcode.motion;
                self.jobs.stepper.held |= braked;
                match motion.hold {
                    Hold::Stopping if braked => motion.hold = Hold::Held,
                    // `~` came while it braked: it goes on now it is at
                    // rest (grbl resumes a hold once it is complete).
                    Hold::None if braked => self.gcode_stepper_send(out),
                    _ => {}
                }
                self.grbl_sync_position();
                false
            }

            _ => false,
        }
    }

    /// The stepper is at rest at `steps`: MPos from the counted steps.
    #[inline(never)]
    fn gcode_stepper_at(&mut self, steps: [i32; 2]) {
        let config = self.stepper_config();
        let at = config
            .joints_of(steps)
            .and_then(|j| config.gimbal.fk(j).ok());
        let motion = &mut self.gcode.motion;
        self.jobs.stepper.inflight = None;
        if let Some(p) = at {
            motion.position = PointMm {
                x_mm: p.x_cm * 10.0,
                y_mm: p.y_cm * 10.0,
            };
        }
    }

    /// The end of homing (`failed`: why it failed), the axes at rest at
    /// `steps`: MPos where homing left the spot (a failed seek moved the
    /// axes too); when a `$H` waits, its reply — `ok` (unlocked) or, as
    /// grbl, `ALARM:N` (locked) and then `ok`; parameters that allow no
    /// homing: `error:5`.
    #[inline(never)]
    pub(in crate::sequencer) fn gcode_homing_done(
        &mut self,
        steps: [i32; 2],
        failed: Option<HomingFailure>,
        out: &mut dyn ActionSink,
    ) {
        if self.gcode.motion.is_idle() {
            self.gcode_stepper_at(steps);
            self.grbl_sync_position();
        }
        if !core::mem::take(&mut self.gcode.homing) {
            return;
        }
        let alarm = match failed {
            None => {
                self.gcode.mode = GrblMode::Normal;
                return self.ok(out);
            }
            Some(HomingFailure::NoSwitches | HomingFailure::BadConfig) => {
                return self.grbl_error(out, GrblError::HomingDisabled);
            }
            Some(HomingFailure::NotFound(_)) => Alarm::HomingNotFound,
            Some(HomingFailure::StillPressed(_)) => Alarm::HomingPullOff,
            Some(HomingFailure::Interrupted) => Alarm::HomingReset,
        };
        self.gcode.mode = GrblMode::Alarm;
        self.grbl_data(out, reply_text(format_args!("ALARM:{}", alarm.code())));
        self.ok(out);
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
    pub(in crate::sequencer) fn gcode_stepper_hold(&mut self, out: &mut dyn ActionSink) -> bool {
        let stepping = self.drivers().hands_over_blocks();
        let motion = &mut self.gcode.motion;
        if !stepping || self.jobs.stepper.inflight.is_none() {
            return false;
        }
        motion.gimbal_lit = false;
        motion.hold = Hold::Stopping;
        self.jobs.stepper.braking = true;
        out.act(Action::Stepper(StepperRequest::Hold));
        true
    }

    /// Whether the stepper reaches board point `p` within its soft limits.
    #[inline(never)]
    pub(in crate::sequencer) fn stepper_reaches(&self, p: PointCm) -> bool {
        let config = self.stepper_config();
        config
            .gimbal
            .ik(BoardPoint::new(p.x_cm, p.y_cm))
            .is_ok_and(|j| config.steps_of(j).is_ok())
    }
}

impl StepperJob {
    /// Whether the stepper runs a move of the job.
    pub(in crate::sequencer) fn is_moving(&self) -> bool {
        self.inflight.is_some()
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
