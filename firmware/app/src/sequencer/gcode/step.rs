//! The G-code step in flight: each actuator that draws gets it
//! ([`Core::gcode_send_step`], the one place that dispatches per
//! actuator: add one here), and reports it done (servo arrival, galvo
//! job done, dwell end); then the next step, block or hold follows.

use crate::domain::Target;
use crate::grbl::{Block, PointMm};
use crate::sequencer::drivers::{Arrival, DriverStep};
use crate::sequencer::gcode::queue::{
    CORNER_DEADBAND_TENTHS, CORNER_SETTLE_MS, Hold, cm, point_at,
};
use crate::sequencer::laser::LaserEvent;
use crate::sequencer::machine::{Action, ActionSink, Core};
use crate::servo::task::ServoOutcome;
use embassy_time::{Duration, Instant};

impl Core {
    /// Sends the current step to every actuator that draws.
    pub(in crate::sequencer) fn gcode_send_step(&mut self, out: &mut dyn ActionSink) {
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
            } => (Some(feed_mm_min), self.gcode_lit(laser.mode, laser.power)),
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
            self.gcode_galvo_send_ahead(out);
        }
    }

    /// The galvo's marking feed for programmed feed `feed_mm_min`: the feed
    /// override applied, capped by the galvo's marking speed
    /// (`galvo.mark_speed_mm_s`), mm/min.
    pub(in crate::sequencer) fn gcode_galvo_feed_mm_min(&self, feed_mm_min: f64) -> f64 {
        let feed = self.gcode.overrides.feed_mm_min(feed_mm_min);
        feed.min(self.settings.galvo.mark_speed_mm_s * 60.0)
    }

    /// A servo move to `to` at `feed` mm/min (rapid: servo speed);
    /// returns its request number.
    pub(in crate::sequencer) fn gcode_servo_move(
        &mut self,
        from: PointMm,
        to: PointMm,
        feed: Option<f64>,
        corner: bool,
        out: &mut dyn ActionSink,
    ) -> Option<u32> {
        let point = cm(to);
        let Ok(aim) = self.aimer.aim(point) else {
            self.grbl_alarm(crate::grbl::Alarm::SoftLimit, out);
            return None;
        };
        let by_servo = self.move_interval_ms(&aim);
        let by_feed = feed.map_or(0.0, |f| {
            let f = self.gcode.overrides.feed_mm_min(f);
            60_000.0 * from.distance_to(to) / f.max(1e-3)
        });
        let interval_ms = libm::fmax(f64::from(by_servo), by_feed).min(f64::from(u16::MAX)) as u16;
        self.gcode.step_speed_ratio =
            crate::sequencer::gcode::power::speed_ratio(by_feed, interval_ms);
        let deadband_tenths = if corner {
            CORNER_DEADBAND_TENTHS
        } else {
            (self.settings.deadband_deg * 10.0) as u16
        };
        let seq = self.send_gimbal_move(&aim, interval_ms, deadband_tenths, out);
        self.last_aim = Some((Target { point, grid: None }, aim));
        Some(seq)
    }

    /// The servo task reports move `seq` arrived; `true` when it was the
    /// G-code step's.
    fn gcode_servo_arrived(&mut self, seq: u32, out: &mut dyn ActionSink) -> bool {
        if self.stream_arrived(seq) {
            out.act(Action::Note(LaserEvent::GimbalArrived));
            return true;
        }
        let Some(c) = self.gcode.motion.current.as_mut() else {
            return false;
        };
        if c.servo_seq != Some(seq) {
            return false;
        }
        c.servo_seq = None;
        if c.index >= c.count && c.count > 0 {
            c.until = Some(
                self.inputs
                    .now
                    .saturating_add(Duration::from_millis(CORNER_SETTLE_MS)),
            );
        }
        self.gcode.motion.arrived = true;
        out.act(Action::Note(LaserEvent::GimbalArrived));
        self.gcode_step_done(out);
        true
    }

    /// The galvo loop finished job `seq`; `true` when it was the G-code
    /// step's.
    pub(in crate::sequencer) fn gcode_galvo_done(
        &mut self,
        seq: u32,
        out: &mut dyn ActionSink,
    ) -> bool {
        let Some(c) = self.gcode.motion.current.as_mut() else {
            return false;
        };
        if c.galvo_seq != Some(seq) {
            return false;
        }
        c.galvo_seq = None;
        self.gcode_galvo_stroke_done(seq, out);
        self.gcode_step_done(out);
        self.gcode_galvo_drop_unadopted(out);
        true
    }

    /// When the dwell deadline passed: the dwell block is done.
    fn gcode_dwell_check(&mut self, out: &mut dyn ActionSink) {
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
            self.gcode_step_done(out);
        }
    }

    /// `run_deadline` (a run's dwell), or when the G-code dwell or settle
    /// ends.
    pub(in crate::sequencer) fn gcode_deadline_or(
        &self,
        run_deadline: Option<Instant>,
    ) -> Option<Instant> {
        run_deadline
            .or(self.gcode.motion.current.and_then(|c| c.until))
            .or_else(|| self.gcode_stepper_power_tick())
    }

    /// Whether G-code lights the gimbal laser now: a lit step or dwell
    /// runs, and the laser mode (`laser auto`) still allows it (`laser off`
    /// mid-step darkens at once).
    pub(in crate::sequencer) fn gcode_gimbal_lit(&self) -> bool {
        self.gcode.motion.gimbal_lit && self.settings.laser_mode == crate::settings::LaserMode::Auto
    }

    /// The dwell deadline passed: a run's dwell, or the G-code step's.
    pub(in crate::sequencer) fn dwell_ended(&mut self, out: &mut dyn ActionSink) {
        self.dwell_finished(out);
        self.gcode_dwell_check(out);
    }

    /// Every actuator finished the step in flight: the next step, the next
    /// block, or the hold.
    pub(in crate::sequencer) fn gcode_step_done(&mut self, out: &mut dyn ActionSink) {
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
                self.grbl_sync_position();
            }
            self.grbl_advance(out);
        } else {
            self.gcode_send_step(out);
        }
    }
}

impl Core {
    /// The G-code side of a servo report: an arrival of the step in flight
    /// moves on; `true` for a fault of it (the caller stops, after its own
    /// fault handling).
    pub(in crate::sequencer) fn gcode_servo_outcome(
        &mut self,
        outcome: &ServoOutcome,
        out: &mut dyn ActionSink,
    ) -> bool {
        match *outcome {
            ServoOutcome::Arrived { seq, .. } => {
                self.gcode_servo_arrived(seq, out);
                false
            }
            ServoOutcome::Fault { seq, .. } => self.gcode_awaits_servo(seq),
            _ => false,
        }
    }

    /// Whether the G-code step waits for servo move `seq`.
    fn gcode_awaits_servo(&self, seq: u32) -> bool {
        self.gcode
            .motion
            .current
            .is_some_and(|c| c.servo_seq == Some(seq))
    }

    /// Whether the G-code step waits for galvo job `seq`.
    pub(in crate::sequencer) fn gcode_awaits_galvo(&self, seq: u32) -> bool {
        self.gcode
            .motion
            .current
            .is_some_and(|c| c.galvo_seq == Some(seq))
            || self.gcode_galvo_ahead_is(seq)
    }
}
