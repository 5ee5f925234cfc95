//! When the laser is on (SPEC §9: off unless a pattern is deliberately
//! drawing).

use crate::settings::LaserMode;
use crate::status::Phase;

/// The laser output (a GPIO on the target, a recorder in the simulator).
pub trait LaserSwitch {
    /// Turns the laser on or off.
    fn set(&mut self, on: bool);

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
