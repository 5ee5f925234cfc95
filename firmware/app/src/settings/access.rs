//! One parameter of the [`Settings`] read or written by its [`ParamSpec`]
//! (`get`/`set`, and storing a value already checked).

use super::error::SettingsError;
use super::spec::{ParamSpec, Slot, check_value};
use super::values::{JumpPlanner, LaserMode, Settings};

impl Settings {
    /// Current value of `param`. (Not inlined: its copy of the settings
    /// stays out of the sequencer task's frame.)
    #[inline(never)]
    pub fn get(&self, param: &ParamSpec) -> f64 {
        let mut copy = *self;
        match param.slot {
            Slot::Real(place) | Slot::Whole(place) | Slot::Baud(place) => *place(&mut copy),
            Slot::Count(place) => f64::from(*place(&mut copy)),
            Slot::Sign(place) => f64::from(*place(&mut copy)),
            Slot::Laser => self.laser_mode.code(),
            Slot::Planner => match self.galvo.planner {
                JumpPlanner::Optimal => 0.0,
                JumpPlanner::Seed => 1.0,
            },
        }
    }

    /// Sets `param` to `value` after checking range, integrality and the
    /// cross-parameter rules; on error nothing changes. (Not inlined, as
    /// [`Settings::get`].)
    #[inline(never)]
    pub fn set(&mut self, param: &ParamSpec, value: f64) -> Result<(), SettingsError> {
        check_value(param, value)?;
        let mut next = *self;
        next.apply(param, value);
        next.validate()?;
        *self = next;
        Ok(())
    }

    /// Stores an already checked value.
    pub(super) fn apply(&mut self, param: &ParamSpec, value: f64) {
        match param.slot {
            Slot::Real(place) | Slot::Whole(place) | Slot::Baud(place) => *place(self) = value,
            Slot::Count(place) => *place(self) = value as u8,
            Slot::Sign(place) => *place(self) = if value < 0.0 { -1 } else { 1 },
            Slot::Laser => {
                if let Some(mode) = LaserMode::from_code(value) {
                    self.laser_mode = mode;
                }
            }
            Slot::Planner => {
                self.galvo.planner = if value == 1.0 {
                    JumpPlanner::Seed
                } else {
                    JumpPlanner::Optimal
                };
            }
        }
    }
}
