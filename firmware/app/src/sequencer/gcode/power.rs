//! Laser power under G-code: S mapped between `$31` and `$30`, the power
//! override applied to S first and the result clamped (as grbl), M3
//! constant, M4 (with `$32=1`) scaled by the actual over the programmed
//! speed. The gimbal's laser output takes the level
//! ([`crate::sequencer::laser::LaserPower`], PWM on the STM32); the galvo's laser is
//! switched per sample, so there S > 0 means on.
//!
//! "Actual speed" on the gimbal: each G-code step is one servo move timed
//! at the programmed feed (feed override applied) unless the servos'
//! speed limit stretches it, so the step's actual speed is its length
//! over its time; at rest (the settle at a block's end, a dwell, a hold)
//! it is 0 and M4 is dark.

use crate::grbl::report::Overrides;
use crate::grbl::{Block, Laser, SpindleMode};
use crate::sequencer::drivers::Driver;
use crate::sequencer::drivers::gimbal::STREAM_PERIOD_MS;
use crate::sequencer::gcode::queue::Hold;
use crate::sequencer::laser::LaserPower;
use crate::sequencer::machine::Core;

/// Actual over programmed speed of a gimbal step that takes `interval_ms`
/// where the programmed feed would take `by_feed_ms`: below 1 when the
/// servos' speed limit stretches it, 0 for a step that does not move.
pub(in crate::sequencer) fn speed_ratio(by_feed_ms: f64, interval_ms: u16) -> f32 {
    if by_feed_ms <= 0.0 {
        return 0.0;
    }
    (by_feed_ms / f64::from(interval_ms.max(1))).clamp(0.0, 1.0) as f32
}

impl Core {
    /// The laser setting of the feed move or dwell that runs (none in a
    /// hold), with the power override applied to S.
    fn gcode_running_laser(&self) -> Option<Laser> {
        let motion = &self.gcode.motion;
        let laser = match motion.current.filter(|_| motion.hold == Hold::None)?.block {
            Block::Line { laser, .. } | Block::Arc { laser, .. } | Block::Dwell { laser, .. } => {
                laser
            }
            _ => return None,
        };
        let percent = f64::from(self.gcode.overrides.spindle);
        Some(Laser {
            mode: laser.mode,
            power: laser.power * percent / 100.0,
        })
    }

    /// The gimbal laser's power: full for the product's own runs; while
    /// G-code lights it, S with the override, × the step's speed ratio
    /// under M4 in laser mode (0 at rest: dark).
    pub(in crate::sequencer) fn gcode_gimbal_power(&self) -> LaserPower {
        if !self.gcode_gimbal_lit() {
            return LaserPower::FULL;
        }
        let Some(laser) = self.gcode_running_laser() else {
            return LaserPower::OFF;
        };
        let v = &self.gcode.values;
        let mut fraction = laser.fraction(v.s_min, v.s_max) as f32;
        if laser.mode == SpindleMode::Dynamic && v.laser_mode {
            let c = self.gcode.motion.current;
            // A streamed block moves while its cursor has speed.
            let streaming = self.jobs.gimbal.speed_mm_s() > 0.0;
            let moving = streaming || c.is_some_and(|c| c.until.is_none() && c.servo_seq.is_some());
            // The stepper: its step generator's speed while its steps run.
            let stepping = self.drivers().any(Driver::polls_speed)
                && c.is_some_and(|c| c.until.is_none())
                && self.jobs.stepper.is_moving();
            fraction *= if stepping {
                f32::from(self.jobs.stepper.speed_permille) / 1000.0
            } else if moving {
                self.gcode.step_speed_ratio
            } else {
                0.0
            };
        }
        LaserPower::from_fraction(fraction)
    }

    /// The stepper's speed over its block's cruise speed, ‰ (0..=1000,
    /// the step generator's; the shell, before each event).
    pub(in crate::sequencer) fn note_stepper_speed(&mut self, permille: u16) {
        self.jobs.stepper.speed_permille = permille;
    }

    /// While G-code lights the stepper's moves: the next time M4 power
    /// follows its speed (the gimbal's stream period after the last event; under M3
    /// nothing changes then), else `None`.
    pub(in crate::sequencer) fn gcode_stepper_power_tick(&self) -> Option<embassy_time::Instant> {
        let lit = self.drivers().any(Driver::polls_speed) && self.gcode_gimbal_lit();
        (lit && self.jobs.stepper.is_moving())
            .then(|| self.inputs.now + embassy_time::Duration::from_millis(STREAM_PERIOD_MS))
    }

    /// After a realtime command: when it changed an override (`before`
    /// the old values), the next status report carries `Ov:` (as grbl's
    /// report counter reset).
    pub(in crate::sequencer) fn grbl_report_changed_overrides(&mut self, before: Overrides) {
        if self.gcode.overrides != before {
            self.gcode.reports = 1;
        }
    }

    /// The power `FS:` reports, in S units: on the galvo the running S
    /// with the override, clamped to `$31`..`$30` (its output is on/off);
    /// elsewhere the level the laser output runs at now (0 when dark).
    pub(in crate::sequencer) fn gcode_reported_power(&self) -> f64 {
        let v = &self.gcode.values;
        let fraction = if self.drivers().any(Driver::reports_programmed_power) {
            self.gcode_running_laser()
                .map_or(0.0, |l| l.fraction(v.s_min, v.s_max))
        } else if self.laser_on && self.gcode_gimbal_lit() {
            f64::from(self.laser_power.per_mille()) / 1000.0
        } else {
            0.0
        };
        if fraction > 0.0 {
            v.s_min + fraction * (v.s_max - v.s_min)
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests;
