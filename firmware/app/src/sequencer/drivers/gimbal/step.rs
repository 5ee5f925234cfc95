//! The gimbal driver's G-code steps: a servo move per step, its arrival.

use crate::domain::Target;
use crate::grbl::PointMm;
use crate::sequencer::gcode::queue::{CORNER_DEADBAND_TENTHS, CORNER_SETTLE_MS, cm};
use crate::sequencer::laser::LaserEvent;
use crate::sequencer::machine::{Action, ActionSink, Core};
use crate::servo::task::ServoOutcome;
use embassy_time::Duration;

impl Core {
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
}
