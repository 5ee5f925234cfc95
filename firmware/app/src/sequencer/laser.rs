//! When the laser is on (SPEC §9: off unless a pattern is deliberately
//! drawing).

use crate::settings::LaserMode;
use crate::status::Phase;

/// The laser output (a GPIO on the target, a recorder in the simulator).
pub trait LaserSwitch {
    /// Turns the laser on or off.
    fn set(&mut self, on: bool);
}

/// Whether the laser should be on, given the mode, the phase of the active
/// run (`None` when idle) and whether a fault is present.
pub fn laser_wanted(mode: LaserMode, phase: Option<Phase>, faulted: bool) -> bool {
    if faulted {
        return false;
    }
    match mode {
        LaserMode::Off => false,
        LaserMode::Auto => phase.is_some(),
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
            for phase in [None, Some(Phase::Moving), Some(Phase::Dwelling)] {
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
}
