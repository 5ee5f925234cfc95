//! The G-code step in flight: the drivers that draw get it through the
//! driver interface ([`Session::send_step`]: a driver's own stage, or
//! [`Session::driver_step`] for each), and report it done (servo arrival,
//! galvo job done, dwell end; each driver's side in `drivers/`); then the
//! next step, block or hold follows.

use crate::grbl::Block;
use crate::sequencer::drivers::{Arrival, DriverJobs, DriverStep, Drivers};
use crate::sequencer::gcode::GcodeSession;
use crate::sequencer::gcode::context::Session;
use crate::sequencer::gcode::queue::{Hold, point_at};
use crate::sequencer::io::ActionSink;
use crate::settings::Settings;
use embassy_time::Instant;

impl Session<'_> {
    /// Sends the current step to every actuator that draws.
    pub(in crate::sequencer) fn send_step(&mut self, out: &mut dyn ActionSink) {
        if self.drivers_send_in_own_stage(out) {
            return;
        }
        let motion = &self.gcode.motion;
        let Some(current) = motion.current else {
            return;
        };
        let to = point_at(&current.block, current.index, current.count);
        let (feed, lit) = match current.block {
            Block::Line {
                feed_mm_min, laser, ..
            }
            | Block::Arc {
                feed_mm_min, laser, ..
            } => (
                Some(feed_mm_min),
                self.gcode.lit(laser.mode, laser.power, self.settings),
            ),
            Block::Jog { feed_mm_min, .. } => (Some(feed_mm_min), false),
            _ => (None, false),
        };
        let lit = lit && motion.hold == Hold::None;
        let from = motion.position;
        let step = DriverStep {
            from,
            to,
            feed,
            lit,
            // The last step of a block ends at a corner: it must arrive
            // within the driver's resolution, or the next block's first
            // step would cut the corner by up to the arrival deadband.
            corner: current.index >= current.count,
        };
        let mut servo_seq = None;
        let mut galvo_seq = None;
        for driver in self.drivers().iter() {
            let Some(seq) = self.driver_step(driver, step, out) else {
                return;
            };
            match driver.arrival() {
                Arrival::Move => servo_seq = Some(seq),
                Arrival::Job => galvo_seq = Some(seq),
            }
            if driver.carries_laser_pin() {
                // Dark until it has arrived once since the start.
                self.gcode.motion.gimbal_lit = lit && self.gcode.motion.arrived;
            }
        }
        if let Some(c) = self.gcode.motion.current.as_mut() {
            c.from = from;
            c.servo_seq = servo_seq;
            c.galvo_seq = galvo_seq;
        }
        if galvo_seq.is_some() {
            self.galvo_send_ahead(out);
        }
    }

    /// When the dwell deadline passed: the dwell block is done.
    pub(in crate::sequencer) fn dwell_check(&mut self, out: &mut dyn ActionSink) {
        let now = self.inputs.now;
        let Some(c) = self.gcode.motion.current.as_mut() else {
            return;
        };
        if c.until.is_some_and(|until| until <= now) {
            c.until = None;
            if self.jobs.gimbal.is_following() {
                // The streaming tick: the next point, or the next block.
                c.servo_seq = None;
                return if c.index > 0 {
                    self.stream_block_done(out)
                } else {
                    self.stream_tick(out)
                };
            }
            self.gcode.motion.gimbal_lit = false;
            self.step_done(out);
        }
    }

    /// Every actuator finished the step in flight: the next step, the next
    /// block, or the hold.
    pub(in crate::sequencer) fn step_done(&mut self, out: &mut dyn ActionSink) {
        let motion = &mut self.gcode.motion;
        let Some(mut c) = motion.current else { return };
        let stepper = c.stepper_seq.is_some();
        if c.servo_seq.is_some() || c.galvo_seq.is_some() || c.until.is_some() || stepper {
            return;
        }
        if c.count > 0 {
            motion.position = point_at(&c.block, c.index, c.count);
        }
        motion.gimbal_lit = false;
        c.index += 1;
        let finished = c.index > c.count || c.cancelled;
        motion.current = (!finished).then_some(c);
        if motion.hold == Hold::Stopping {
            motion.hold = Hold::Held;
            return;
        }
        if finished {
            if c.cancelled {
                self.gcode.sync_position();
            }
            self.advance(out);
        } else {
            self.send_step(out);
        }
    }
}

impl GcodeSession {
    /// `run_deadline` (a run's dwell), or when the G-code dwell or settle
    /// ends, or the next M4 power tick of a driver polled for its speed
    /// ([`GcodeSession::stepper_power_tick`]; `now`: the event's time).
    pub(in crate::sequencer) fn deadline_or(
        &self,
        run_deadline: Option<Instant>,
        (settings, jobs, drivers): (&Settings, &DriverJobs, Drivers),
        now: Instant,
    ) -> Option<Instant> {
        run_deadline
            .or(self.motion.current.and_then(|c| c.until))
            .or_else(|| self.stepper_power_tick(settings, jobs, drivers, now))
    }
}
