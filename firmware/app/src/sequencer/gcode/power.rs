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
use crate::sequencer::drivers::gimbal::STREAM_PERIOD_MS;
use crate::sequencer::drivers::{Driver, DriverJobs, Drivers};
use crate::sequencer::gcode::GcodeSession;
use crate::sequencer::gcode::queue::Hold;
use crate::sequencer::laser::LaserPower;
use crate::settings::{LaserMode, Settings};
use embassy_time::Instant;

/// Actual over programmed speed of a gimbal step that takes `interval_ms`
/// where the programmed feed would take `by_feed_ms`: below 1 when the
/// servos' speed limit stretches it, 0 for a step that does not move.
pub(in crate::sequencer) fn speed_ratio(by_feed_ms: f64, interval_ms: u16) -> f32 {
    if by_feed_ms <= 0.0 {
        return 0.0;
    }
    (by_feed_ms / f64::from(interval_ms.max(1))).clamp(0.0, 1.0) as f32
}

/// What the session reads of the core for its laser power and its
/// status reports.
pub(in crate::sequencer) struct Seen<'a> {
    /// The product's settings (laser mode, marking speeds).
    pub(in crate::sequencer) settings: &'a Settings,
    /// What each driver keeps of the G-code job (their speeds).
    pub(in crate::sequencer) jobs: &'a DriverJobs,
    /// The driver(s) that draw.
    pub(in crate::sequencer) drivers: Drivers,
    /// Whether the gimbal laser is on, and at what power.
    pub(in crate::sequencer) laser: Option<LaserPower>,
    /// The stepper task homes.
    pub(in crate::sequencer) stepper_homing: bool,
    /// The laser controls' door substate (`None`: not held by them).
    pub(in crate::sequencer) door: Option<u8>,
}

impl GcodeSession {
    /// Whether G-code lights the gimbal laser now: a lit step or dwell
    /// runs, and the laser mode (`laser auto`) of `settings` still allows
    /// it (`laser off` mid-step darkens at once).
    pub(in crate::sequencer) fn gimbal_lit(&self, settings: &Settings) -> bool {
        self.motion.gimbal_lit && settings.laser_mode == LaserMode::Auto
    }

    /// The laser setting of the feed move or dwell that runs (none in a
    /// hold), with the power override applied to S.
    fn running_laser(&self) -> Option<Laser> {
        let motion = &self.motion;
        let laser = match motion.current.filter(|_| motion.hold == Hold::None)?.block {
            Block::Line { laser, .. } | Block::Arc { laser, .. } | Block::Dwell { laser, .. } => {
                laser
            }
            _ => return None,
        };
        let percent = f64::from(self.overrides.spindle);
        Some(Laser {
            mode: laser.mode,
            power: laser.power * percent / 100.0,
        })
    }

    /// The gimbal laser's power: full for the product's own runs; while
    /// G-code lights it, S with the override, × the step's speed ratio
    /// under M4 in laser mode (0 at rest: dark). `settings`, `jobs` and
    /// `drivers` as in [`Seen`].
    pub(in crate::sequencer) fn gimbal_power(
        &self,
        settings: &Settings,
        jobs: &DriverJobs,
        drivers: Drivers,
    ) -> LaserPower {
        if !self.gimbal_lit(settings) {
            return LaserPower::FULL;
        }
        let Some(laser) = self.running_laser() else {
            return LaserPower::OFF;
        };
        let v = &self.values;
        let mut fraction = laser.fraction(v.s_min, v.s_max) as f32;
        if laser.mode == SpindleMode::Dynamic && v.laser_mode {
            let c = self.motion.current;
            // A streamed block moves while its cursor has speed.
            let streaming = jobs.gimbal.speed_mm_s() > 0.0;
            let moving = streaming || c.is_some_and(|c| c.until.is_none() && c.servo_seq.is_some());
            // The stepper: its step generator's speed while its steps run.
            let stepping = drivers.any(Driver::polls_speed)
                && c.is_some_and(|c| c.until.is_none())
                && jobs.stepper.is_moving();
            fraction *= if stepping {
                f32::from(jobs.stepper.speed_permille) / 1000.0
            } else if moving {
                self.step_speed_ratio
            } else {
                0.0
            };
        }
        LaserPower::from_fraction(fraction)
    }

    /// While G-code lights the stepper's moves: the next time M4 power
    /// follows its speed (the gimbal's stream period after `now`, the
    /// last event; under M3 nothing changes then), else `None`.
    pub(in crate::sequencer) fn stepper_power_tick(
        &self,
        settings: &Settings,
        jobs: &DriverJobs,
        drivers: Drivers,
        now: Instant,
    ) -> Option<Instant> {
        let lit = drivers.any(Driver::polls_speed) && self.gimbal_lit(settings);
        (lit && jobs.stepper.is_moving())
            .then(|| now + embassy_time::Duration::from_millis(STREAM_PERIOD_MS))
    }

    /// After a realtime command: when it changed an override (`before`
    /// the old values), the next status report carries `Ov:` (as grbl's
    /// report counter reset).
    pub(in crate::sequencer) fn note_overrides(&mut self, before: Overrides) {
        if self.overrides != before {
            self.reports = 1;
        }
    }

    /// The power `FS:` reports, in S units: on the galvo the running S
    /// with the override, clamped to `$31`..`$30` (its output is on/off);
    /// elsewhere the level the laser output runs at now (0 when dark).
    pub(in crate::sequencer) fn reported_power(&self, seen: &Seen<'_>) -> f64 {
        let v = &self.values;
        let fraction = if seen.drivers.any(Driver::reports_programmed_power) {
            self.running_laser()
                .map_or(0.0, |l| l.fraction(v.s_min, v.s_max))
        } else if let Some(level) = seen.laser.filter(|_| self.gimbal_lit(seen.settings)) {
            f64::from(level.per_mille()) / 1000.0
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
