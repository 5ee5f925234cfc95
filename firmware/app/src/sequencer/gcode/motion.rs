//! Running the motion queue: blocks started, held, resumed, aborted.

use crate::grbl::{Block, SpindleMode};
use crate::sequencer::drivers::{Driver, Drivers};
use crate::sequencer::gcode::GcodeSession;
use crate::sequencer::gcode::context::Session;
use crate::sequencer::gcode::queue::{Current, Hold, MAX_STEPS};
use crate::sequencer::gcode::report;
use crate::sequencer::io::{Action, ActionSink};
use crate::sequencer::laser::LaserEvent;
use embassy_time::Duration;

impl Session<'_> {
    /// Starts the next block when nothing runs (and no hold), skipping
    /// blocks with nothing to move.
    pub(in crate::sequencer) fn advance(&mut self, out: &mut dyn ActionSink) {
        while self.gcode.motion.current.is_none() && self.gcode.motion.hold == Hold::None {
            let Some(block) = self.gcode.motion.queue.pop_front() else {
                return;
            };
            self.gcode.take_owed(out);
            if !self.gcode.motion.started {
                // A G-code job starts like a run: what ran stops, nothing
                // of it may shine.
                if let Some(run) = self.run.take() {
                    crate::log::info!("stop {} (G-code started)", run.kind.name());
                    out.act(Action::Note(LaserEvent::Stopped {
                        why: "G-code started",
                    }));
                }
                out.act(Action::Note(LaserEvent::RunStarted));
                self.close_gate(out);
                self.gcode.motion.started = true;
            }
            match block {
                Block::Pause => self.gcode.motion.hold = Hold::Held,
                Block::End => {}
                Block::Dwell { seconds, laser } => {
                    let until = self
                        .inputs
                        .now
                        .saturating_add(Duration::from_micros((seconds.max(0.0) * 1e6) as u64));
                    let g = &mut self.gcode;
                    g.motion.gimbal_lit = g.lit(laser.mode, laser.power, self.settings)
                        && laser.mode == SpindleMode::Constant;
                    g.motion.current = Some(g.new_current(block, 0));
                    if let Some(c) = self.gcode.motion.current.as_mut() {
                        c.until = Some(until);
                    }
                }
                _ => {
                    if self.drivers_take_block(&block, out) {
                        continue;
                    }
                    let (path_step_cm, drivers) = (self.aimer.path_step_cm(), self.drivers());
                    let g = &mut self.gcode;
                    let count = g.step_count(&block, path_step_cm, drivers);
                    g.motion.current = Some(g.new_current(block, count));
                    self.send_step(out);
                }
            }
        }
    }

    /// `!`: laser dark at once; the gimbal stops after the step in
    /// flight, the galvo brakes along its stroke (held where it reports
    /// marking stopped).
    pub(in crate::sequencer) fn hold(&mut self, out: &mut dyn ActionSink) {
        let motion = &self.gcode.motion;
        if motion.hold != Hold::None
            || motion.is_idle()
            || self.with_stage(out, |st, jobs, out| jobs.stepper.hold(st, out))
        {
            return;
        }
        let motion = &mut self.gcode.motion;
        motion.gimbal_lit = false;
        let galvo_in_flight = motion.current.is_some_and(|c| c.galvo_seq.is_some());
        // A galvo stroke: held where the galvo reports it stopped marking.
        let (current, lockstep) = (motion.current, self.drivers().lockstep());
        let stroke = self.jobs.galvo.hold(current, lockstep);
        let motion = &mut self.gcode.motion;
        if let Some(c) = motion.current.as_mut() {
            // Its `done` no longer counts: a galvo step (not a stroke) is
            // redone from its start on resume.
            c.galvo_seq = None;
        }
        // A dwell runs to its end, dark; a servo move to its point.
        let waiting = motion
            .current
            .is_some_and(|c| c.servo_seq.is_some() || c.until.is_some());
        motion.hold = if waiting || stroke {
            Hold::Stopping
        } else {
            Hold::Held
        };
        if galvo_in_flight {
            // Closing the gate also darkens the samples the DAC holds.
            self.close_gate(out);
        }
    }

    /// `~`: resumes after a hold (or an M0 pause).
    pub(in crate::sequencer) fn resume(&mut self, out: &mut dyn ActionSink) {
        let motion = &mut self.gcode.motion;
        match motion.hold {
            Hold::None => {}
            Hold::Stopping => motion.hold = Hold::None,
            Hold::Held => {
                motion.hold = Hold::None;
                if motion.current.is_some() {
                    self.send_step(out);
                } else {
                    self.advance(out);
                }
            }
        }
    }

    /// 0x85: the jog stops after the step in flight; queued jogs dropped.
    pub(in crate::sequencer) fn jog_cancel(&mut self, out: &mut dyn ActionSink) {
        if !self.gcode.motion.jogging() {
            return;
        }
        let motion = &mut self.gcode.motion;
        motion.queue.clear();
        let Some(c) = motion.current.as_mut() else {
            return;
        };
        c.cancelled = true;
        if c.galvo_seq.take().is_some() {
            crate::sequencer::drivers::stage::stop_galvo(self.inputs, out);
            self.step_done(out);
        }
    }

    /// A stop from anywhere (`stop`, the button, a fault, a reset, an
    /// alarm): the queue is dropped; a line waiting for room is answered.
    pub(in crate::sequencer) fn abort(&mut self, out: &mut dyn ActionSink) {
        self.jobs.gimbal.clear();
        self.jobs.stepper.clear();
        if self.gcode.motion.clear() {
            report::ok(out);
        }
        self.jobs.galvo.hold_dropped();
        self.gcode.sync_position();
    }
}

impl GcodeSession {
    /// The block that starts running now, `count` steps, from where the
    /// spot is.
    pub(in crate::sequencer) fn new_current(&self, block: Block, count: u32) -> Current {
        Current {
            block,
            index: 1,
            count,
            from: self.motion.position,
            servo_seq: None,
            galvo_seq: None,
            stepper_seq: None,
            until: None,
            cancelled: false,
        }
    }

    /// Steps `block` is split into on the current actuator(s).
    /// `path_step_cm`: the geometry's path step; `drivers`: the driver(s)
    /// that draw.
    fn step_count(&self, block: &Block, path_step_cm: f64, drivers: Drivers) -> u32 {
        // One arc sent as its chords would be drawn as that many whole
        // arcs by a driver that takes arcs whole (each from its end: a
        // full circle each).
        if matches!(block, Block::Arc { .. }) && drivers.any(Driver::takes_arcs_whole) {
            return 1;
        }
        let step_mm = crate::domain::units::mm_from_cm(path_step_cm).max(0.01);
        let gimbal = drivers.any(Driver::steps_lines);
        let steps =
            |length_mm: f64| libm::ceil(length_mm / step_mm).clamp(1.0, MAX_STEPS as f64) as u32;
        match *block {
            Block::Rapid { .. } => 1,
            Block::Line { from, to, .. } | Block::Jog { from, to, .. } if gimbal => {
                steps(from.distance_to(to))
            }
            Block::Arc { arc, .. } => {
                let chords = arc.segment_count(self.values.arc_tolerance_mm, MAX_STEPS);
                if gimbal {
                    chords.max(steps(arc.length_mm()))
                } else {
                    chords
                }
            }
            _ => 1,
        }
    }
}
