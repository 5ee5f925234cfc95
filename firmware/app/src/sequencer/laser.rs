//! When the laser is on (SPEC §9: off unless a pattern is deliberately
//! drawing).

use crate::settings::LaserMode;
use crate::status::Phase;

/// Laser output power: the duty of the laser output, per mille of full
/// power (0 dark, 1000 full). Outputs that can only switch (the galvo's
/// per-sample laser words) treat every level above 0 as on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LaserPower(u16);

impl LaserPower {
    /// Dark.
    pub const OFF: Self = Self(0);
    /// Full power (duty 100 %).
    pub const FULL: Self = Self(1000);

    /// The level for `fraction` of full power (0..=1; clamped, NaN dark),
    /// rounded to the nearest per mille.
    pub fn from_fraction(fraction: f32) -> Self {
        // `as` saturates and maps NaN to 0.
        Self((fraction.clamp(0.0, 1.0) * 1000.0 + 0.5) as u16)
    }

    /// Duty, per mille of full power (0..=1000).
    pub fn per_mille(self) -> u16 {
        self.0
    }

    /// Whether the laser shines at all.
    pub fn is_on(self) -> bool {
        self.0 > 0
    }

    /// `full_scale` × this duty, rounded down: the compare value of a
    /// PWM timer whose period is `full_scale` counts.
    pub fn scaled(self, full_scale: u32) -> u32 {
        full_scale * u32::from(self.0) / 1000
    }
}

/// The laser output (a GPIO or PWM channel on the target, a recorder in
/// the simulator).
pub trait LaserSwitch {
    /// Sets the laser's power ([`LaserPower::OFF`]: dark). An output that
    /// can only switch turns on for every level above 0.
    fn set(&mut self, power: LaserPower);

    /// Told when the sequencer processes an event that decides whether a
    /// laser may be lit ([`LaserEvent`]). Only for recorders: the
    /// simulator timestamps these for its safety checker. The default
    /// (the target's pin) ignores them; it never changes what the
    /// firmware does.
    fn note(&mut self, _event: LaserEvent<'_>) {}
}

/// Sequencer events that decide when a laser may be lit (see
/// [`LaserSwitch::note`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LaserEvent<'a> {
    /// The sequencer stopped (`stop` command, stop button, servo fault,
    /// galvo underrun, actuator change, pattern complete, …): every laser
    /// must be dark from now on. `why` is the reason as logged.
    Stopped {
        /// Why, as in the log (`"stop command"`, `"servo fault"`, …).
        why: &'a str,
    },
    /// A pattern or goto started (lights are allowed again, per the
    /// laser mode).
    RunStarted,
    /// A servo move was sent: the gimbal has left its point.
    GimbalMoveSent,
    /// The servo task confirmed the gimbal's arrival at the current point.
    GimbalArrived,
}

/// Whether the laser should be on, given the mode, the phase of the active
/// run (`None` when idle) and whether a fault is present.
///
/// Travel to the first point of a pass or to a goto target
/// ([`Phase::Approaching`]) is dark in every mode: the spot is not on the
/// figure yet. `auto` lights from the arrival there on, the moves between
/// the figure's points included; `dwell` only while dwelling or holding.
pub fn laser_wanted(mode: LaserMode, phase: Option<Phase>, faulted: bool) -> bool {
    if faulted {
        return false;
    }
    match mode {
        LaserMode::Off => false,
        LaserMode::Auto => matches!(
            phase,
            Some(Phase::Moving | Phase::Dwelling | Phase::Holding)
        ),
        LaserMode::Dwell => matches!(phase, Some(Phase::Dwelling | Phase::Holding)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_levels_round_clamp_and_scale() {
        assert_eq!(LaserPower::from_fraction(0.3).per_mille(), 300);
        assert_eq!(LaserPower::from_fraction(0.0005), LaserPower(1));
        assert_eq!(LaserPower::from_fraction(1.7), LaserPower::FULL);
        assert_eq!(LaserPower::from_fraction(-0.2), LaserPower::OFF);
        assert_eq!(LaserPower::from_fraction(f32::NAN), LaserPower::OFF);
        assert!(!LaserPower::OFF.is_on() && LaserPower(1).is_on());
        assert_eq!(LaserPower(300).scaled(42_000), 12_600);
        assert_eq!(LaserPower::FULL.scaled(42_000), 42_000);
    }

    #[test]
    fn laser_is_off_when_idle_or_faulted() {
        for mode in [LaserMode::Auto, LaserMode::Dwell, LaserMode::Off] {
            assert!(!laser_wanted(mode, None, false));
        }
        for mode in [LaserMode::Auto, LaserMode::Dwell, LaserMode::Off] {
            for phase in [
                None,
                Some(Phase::Approaching),
                Some(Phase::Moving),
                Some(Phase::Dwelling),
            ] {
                assert!(!laser_wanted(mode, phase, true));
            }
        }
    }

    #[test]
    fn modes_decide_when_a_run_is_active() {
        assert!(laser_wanted(LaserMode::Auto, Some(Phase::Moving), false));
        assert!(laser_wanted(LaserMode::Auto, Some(Phase::Dwelling), false));
        assert!(!laser_wanted(LaserMode::Dwell, Some(Phase::Moving), false));
        assert!(laser_wanted(LaserMode::Dwell, Some(Phase::Dwelling), false));
        assert!(laser_wanted(LaserMode::Dwell, Some(Phase::Holding), false));
        assert!(!laser_wanted(LaserMode::Off, Some(Phase::Dwelling), false));
    }

    #[test]
    fn travel_to_the_figure_is_dark_in_every_mode() {
        for mode in [LaserMode::Auto, LaserMode::Dwell, LaserMode::Off] {
            assert!(!laser_wanted(mode, Some(Phase::Approaching), false));
        }
    }
}
