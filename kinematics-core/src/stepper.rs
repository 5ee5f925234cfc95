//! Stepper axis mapping (SPEC §4.4, seed: stepper light-spot): joint angle
//! ↔ microsteps. The seed drives 1.8° motors at 32 microsteps, 0.05625° per
//! step, and converts with `step = angle / 0.05625`.
//!
//! The seed's pointing geometry (`angle_x = atan(x / op)`,
//! `angle_y = atan(y / √(x² + op²))`) is the exact gimbal model with
//! OL = 0, so a stepper pan/tilt uses [`crate::gimbal::exact`] with
//! `ol_cm = 0` for its joint angles and this module for the steps.
//!
//! Motion in grbl's shape (seed: grbl-pan-tilt-controller): moves in
//! microsteps enter the look-ahead [`Planner`], the [`SegmentPrep`] cuts the
//! planned profiles into short constant-rate [`Segment`]s ahead of time, and
//! the [`StepGenerator`] only executes those (Bresenham, integers only).

#[cfg(test)]
mod feed_tests;
#[cfg(test)]
mod hold_tests;
pub mod motion;
#[cfg(test)]
mod motion_tests;
pub mod planner;
pub mod segment;
pub mod step_gen;

pub use motion::MotionError;
pub use planner::{PlannedBlock, Planner, StepMove, junction_rate_steps_per_s};
pub use segment::{Profile, Segment, SegmentPrep, SegmentQueue, StepBlock};
pub use step_gen::{StepGenerator, StepTick};

use crate::error::Error;
use crate::numeric::finite;
use crate::servo::Direction;

/// The seed's motor: 1.8° full step.
pub const SEED_FULL_STEP_DEG: f64 = 1.8;
/// The seed's driver setting: 32 microsteps per full step.
pub const SEED_MICROSTEPS: u16 = 32;

/// Calibration of one stepper axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepperAxis {
    /// Joint degrees per microstep (> 0).
    pub deg_per_step: f64,
    /// Sign of the step count vs the joint angle.
    pub direction: Direction,
}

impl Default for StepperAxis {
    /// The seed's 1.8° / 32 = 0.05625° per microstep, normal direction.
    fn default() -> Self {
        Self {
            deg_per_step: SEED_FULL_STEP_DEG / f64::from(SEED_MICROSTEPS),
            direction: Direction::Normal,
        }
    }
}

impl StepperAxis {
    /// An axis for a motor with `full_step_deg` (> 0) per full step driven
    /// at `microsteps` (≥ 1) microsteps per full step.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`].
    pub fn from_motor(full_step_deg: f64, microsteps: u16) -> Result<Self, Error> {
        if microsteps == 0 {
            return Err(Error::InvalidConfig {
                what: "microsteps must be >= 1",
            });
        }
        let axis = Self {
            deg_per_step: finite(full_step_deg, "full_step_deg")? / f64::from(microsteps),
            direction: Direction::Normal,
        };
        axis.validate()?;
        Ok(axis)
    }

    fn validate(&self) -> Result<(), Error> {
        if finite(self.deg_per_step, "deg_per_step")? <= 0.0 {
            return Err(Error::InvalidConfig {
                what: "deg_per_step must be > 0",
            });
        }
        Ok(())
    }

    /// Nearest microstep count (from the zero position) for `angle_deg`.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`],
    /// [`Error::StepsOutOfRange`].
    pub fn angle_to_steps(&self, angle_deg: f64) -> Result<i32, Error> {
        self.validate()?;
        let steps = libm::round(
            self.direction.sign() * finite(angle_deg, "angle_deg")? / self.deg_per_step,
        );
        if !(steps >= f64::from(i32::MIN) && steps <= f64::from(i32::MAX)) {
            return Err(Error::StepsOutOfRange);
        }
        // In range and whole: the cast is exact.
        Ok(steps as i32)
    }

    /// Joint angle (degrees) of a microstep count.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`].
    pub fn steps_to_angle(&self, steps: i32) -> Result<f64, Error> {
        self.validate()?;
        Ok(self.direction.sign() * f64::from(steps) * self.deg_per_step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn seed_resolution() {
        let s = StepperAxis::default();
        assert_eq!(s.deg_per_step, 0.05625);
        // One full step is 32 microsteps; a quarter turn 1600; a turn 6400.
        assert_eq!(s.angle_to_steps(1.8).unwrap(), 32);
        assert_eq!(s.angle_to_steps(90.0).unwrap(), 1600);
        assert_eq!(s.angle_to_steps(-360.0).unwrap(), -6400);
        assert_eq!(s.steps_to_angle(16).unwrap(), 0.9);
        // Seed: step_x = angle_x / 0.05625, nearest step.
        assert_eq!(s.angle_to_steps(0.03).unwrap(), 1);
        assert_eq!(s.angle_to_steps(0.02).unwrap(), 0);
        let rev = StepperAxis {
            direction: Direction::Reversed,
            ..s
        };
        assert_eq!(rev.angle_to_steps(1.8).unwrap(), -32);
        assert_eq!(rev.steps_to_angle(-32).unwrap(), 1.8);
    }

    #[test]
    fn errors() {
        let s = StepperAxis::default();
        assert_eq!(s.angle_to_steps(1e12), Err(Error::StepsOutOfRange));
        assert_eq!(
            s.angle_to_steps(f64::NAN),
            Err(Error::NonFinite { what: "angle_deg" })
        );
        let bad = StepperAxis {
            deg_per_step: 0.0,
            ..s
        };
        assert!(matches!(
            bad.steps_to_angle(1),
            Err(Error::InvalidConfig { .. })
        ));
        assert!(matches!(
            StepperAxis::from_motor(1.8, 0),
            Err(Error::InvalidConfig { .. })
        ));
        assert!(matches!(
            StepperAxis::from_motor(-1.8, 16),
            Err(Error::InvalidConfig { .. })
        ));
        assert_eq!(
            StepperAxis::from_motor(f64::NAN, 16),
            Err(Error::NonFinite {
                what: "full_step_deg"
            })
        );
        // 0.9° motor at 16 microsteps.
        assert_eq!(
            StepperAxis::from_motor(0.9, 16).unwrap().deg_per_step,
            0.05625
        );
    }

    proptest! {
        #[test]
        fn steps_angle_steps_is_identity(steps in -1_000_000i32..1_000_000) {
            let s = StepperAxis::default();
            prop_assert_eq!(s.angle_to_steps(s.steps_to_angle(steps).unwrap()).unwrap(), steps);
        }

        #[test]
        fn angle_steps_angle_within_half_a_step(angle in -720.0f64..720.0) {
            let s = StepperAxis::default();
            let back = s.steps_to_angle(s.angle_to_steps(angle).unwrap()).unwrap();
            prop_assert!((back - angle).abs() <= 0.05625 / 2.0 + 1e-12);
        }
    }
}
