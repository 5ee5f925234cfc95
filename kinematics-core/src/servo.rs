//! Servo angle mapping (SPEC §4.4): joint angle ↔ servo angle ↔ FashionStar
//! wire value.
//!
//! `servo_deg = direction · scale · joint_deg + zero_deg`, limited to
//! `[min_deg, max_deg]` and quantised to the servo's 0.1° resolution: the
//! wire value is `round(10 · servo_deg)` as an `i16` (tenths of a degree).

use crate::error::{Error, Joint};
use crate::numeric::{clamp, finite};

/// Wire units (FashionStar angle field) per degree: the field is in 0.1°.
pub const WIRE_PER_DEG: f64 = 10.0;

/// Largest |servo angle| an `i16` wire value can carry, degrees.
pub const WIRE_RANGE_DEG: f64 = i16::MAX as f64 / WIRE_PER_DEG;

/// SPEC default servo range: ±135°.
pub const DEFAULT_LIMIT_DEG: f64 = 135.0;

/// Sign of the servo angle relative to the joint angle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Direction {
    /// Servo angle increases with the joint angle (+1).
    #[default]
    Normal,
    /// Servo angle decreases as the joint angle increases (−1).
    Reversed,
}

impl Direction {
    /// +1.0 or −1.0.
    pub fn sign(self) -> f64 {
        match self {
            Direction::Normal => 1.0,
            Direction::Reversed => -1.0,
        }
    }

    /// `Normal` for +1, `Reversed` for −1, `None` otherwise.
    pub fn from_sign(sign: i8) -> Option<Self> {
        match sign {
            1 => Some(Direction::Normal),
            -1 => Some(Direction::Reversed),
            _ => None,
        }
    }
}

/// Calibration of one servo axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoAxis {
    /// Sign of servo angle vs joint angle.
    pub direction: Direction,
    /// Servo degrees per joint degree (gear / calibration error), > 0.
    pub scale: f64,
    /// Servo angle at joint angle 0, degrees.
    pub zero_deg: f64,
    /// Lowest allowed servo angle, degrees.
    pub min_deg: f64,
    /// Highest allowed servo angle, degrees.
    pub max_deg: f64,
}

impl Default for ServoAxis {
    /// SPEC defaults: direction +1, scale 1, zero 0, limits ±135°.
    fn default() -> Self {
        Self {
            direction: Direction::Normal,
            scale: 1.0,
            zero_deg: 0.0,
            min_deg: -DEFAULT_LIMIT_DEG,
            max_deg: DEFAULT_LIMIT_DEG,
        }
    }
}

impl ServoAxis {
    /// Checks the calibration: finite, `scale > 0`, `min_deg < max_deg`,
    /// limits within the wire range (±3276.7°) and at least one 0.1° step
    /// apart.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`].
    pub fn validate(&self) -> Result<(), Error> {
        finite(self.scale, "servo scale")?;
        finite(self.zero_deg, "servo zero_deg")?;
        finite(self.min_deg, "servo min_deg")?;
        finite(self.max_deg, "servo max_deg")?;
        if self.scale <= 0.0 {
            return Err(Error::InvalidConfig {
                what: "servo scale must be > 0",
            });
        }
        if self.min_deg < -WIRE_RANGE_DEG || self.max_deg > WIRE_RANGE_DEG {
            return Err(Error::InvalidConfig {
                what: "servo limits must be within the i16 wire range (+-3276.7 deg)",
            });
        }
        let (lo, hi) = self.wire_limits();
        if lo > hi || self.min_deg >= self.max_deg {
            return Err(Error::InvalidConfig {
                what: "servo min_deg must be below max_deg",
            });
        }
        Ok(())
    }

    /// Lowest and highest wire value inside the limits.
    fn wire_limits(&self) -> (f64, f64) {
        (
            libm::ceil(self.min_deg * WIRE_PER_DEG),
            libm::floor(self.max_deg * WIRE_PER_DEG),
        )
    }

    /// Servo angle (degrees) for a joint angle (degrees), checked against
    /// the limits. `joint` only labels the error.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`],
    /// [`Error::JointLimit`].
    pub fn joint_to_servo_deg(&self, joint: Joint, joint_deg: f64) -> Result<f64, Error> {
        self.validate()?;
        let joint_deg = finite(joint_deg, joint.name())?;
        let servo_deg = self.direction.sign() * self.scale * joint_deg + self.zero_deg;
        if !(servo_deg >= self.min_deg && servo_deg <= self.max_deg) {
            return Err(Error::JointLimit {
                joint,
                servo_deg,
                min_deg: self.min_deg,
                max_deg: self.max_deg,
            });
        }
        Ok(servo_deg)
    }

    /// Joint angle (degrees) → wire value (servo angle in 0.1°, rounded
    /// half away from zero and kept inside the limits).
    ///
    /// Errors: as [`joint_to_servo_deg`](Self::joint_to_servo_deg).
    pub fn joint_to_wire(&self, joint: Joint, joint_deg: f64) -> Result<i16, Error> {
        let servo_deg = self.joint_to_servo_deg(joint, joint_deg)?;
        let (lo, hi) = self.wire_limits();
        let wire = clamp(libm::round(servo_deg * WIRE_PER_DEG), lo, hi);
        // Validated: lo..=hi lies within i16, so the cast is exact.
        Ok(wire as i16)
    }

    /// Servo angle (degrees) → joint angle (degrees). No limit check: a
    /// reported position is what it is.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`].
    pub fn servo_deg_to_joint(&self, servo_deg: f64) -> Result<f64, Error> {
        self.validate()?;
        let servo_deg = finite(servo_deg, "servo_deg")?;
        Ok((servo_deg - self.zero_deg) / (self.direction.sign() * self.scale))
    }

    /// Wire value (0.1°) → joint angle (degrees).
    ///
    /// Errors: [`Error::InvalidConfig`] (invalid calibration).
    pub fn wire_to_joint(&self, wire: i16) -> Result<f64, Error> {
        self.servo_deg_to_joint(f64::from(wire) / WIRE_PER_DEG)
    }

    /// The joint-angle interval (degrees) that maps inside the servo limits.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`].
    pub fn joint_range_deg(&self) -> Result<(f64, f64), Error> {
        let a = self.servo_deg_to_joint(self.min_deg)?;
        let b = self.servo_deg_to_joint(self.max_deg)?;
        Ok((a.min(b), a.max(b)))
    }
}

/// FashionStar wire values of both gimbal servos (tenths of a degree).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WireAngles {
    /// Yaw servo angle, 0.1°.
    pub yaw: i16,
    /// Pitch servo angle, 0.1°.
    pub pitch: i16,
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn default_mapping_is_tenths_of_a_degree() {
        let s = ServoAxis::default();
        assert_eq!(s.joint_to_wire(Joint::Yaw, 12.34).unwrap(), 123);
        assert_eq!(s.joint_to_wire(Joint::Yaw, 12.36).unwrap(), 124);
        assert_eq!(s.joint_to_wire(Joint::Yaw, -45.0).unwrap(), -450);
        assert_eq!(s.joint_to_wire(Joint::Yaw, 135.0).unwrap(), 1350);
        assert_eq!(s.wire_to_joint(-1234).unwrap(), -123.4);
    }

    #[test]
    fn direction_scale_and_zero_hand_computed() {
        let s = ServoAxis {
            direction: Direction::Reversed,
            scale: 2.0,
            zero_deg: 10.0,
            min_deg: -100.0,
            max_deg: 100.0,
        };
        // −1 · 2 · 5 + 10 = 0.
        assert_eq!(s.joint_to_servo_deg(Joint::Pitch, 5.0).unwrap(), 0.0);
        // −1 · 2 · (−20) + 10 = 50 → wire 500.
        assert_eq!(s.joint_to_wire(Joint::Pitch, -20.0).unwrap(), 500);
        // wire 300 = 30° → joint (30 − 10) / (−2) = −10.
        assert_eq!(s.wire_to_joint(300).unwrap(), -10.0);
        // Joint range: servo −100 ↔ joint 55, servo 100 ↔ joint −45.
        assert_eq!(s.joint_range_deg().unwrap(), (-45.0, 55.0));
    }

    #[test]
    fn limits_are_errors_and_quantisation_stays_inside() {
        let s = ServoAxis::default();
        assert_eq!(
            s.joint_to_wire(Joint::Pitch, 135.2),
            Err(Error::JointLimit {
                joint: Joint::Pitch,
                servo_deg: 135.2,
                min_deg: -135.0,
                max_deg: 135.0
            })
        );
        // A limit between two 0.1° steps: the rounded value may not cross it.
        let s = ServoAxis {
            max_deg: 90.06,
            ..ServoAxis::default()
        };
        // round(900.6) = 901 would be 90.1° > 90.06°: kept at 900.
        assert_eq!(s.joint_to_wire(Joint::Yaw, 90.06).unwrap(), 900);
    }

    #[test]
    fn invalid_calibration_and_input_are_errors() {
        let bad_scale = ServoAxis {
            scale: 0.0,
            ..ServoAxis::default()
        };
        assert!(matches!(
            bad_scale.joint_to_wire(Joint::Yaw, 1.0),
            Err(Error::InvalidConfig { .. })
        ));
        assert!(matches!(
            bad_scale.wire_to_joint(10),
            Err(Error::InvalidConfig { .. })
        ));
        let inverted = ServoAxis {
            min_deg: 10.0,
            max_deg: -10.0,
            ..ServoAxis::default()
        };
        assert!(matches!(
            inverted.validate(),
            Err(Error::InvalidConfig { .. })
        ));
        let narrow = ServoAxis {
            min_deg: 1.01,
            max_deg: 1.09,
            ..ServoAxis::default()
        };
        assert!(matches!(
            narrow.validate(),
            Err(Error::InvalidConfig { .. })
        ));
        let huge = ServoAxis {
            max_deg: 4000.0,
            ..ServoAxis::default()
        };
        assert!(matches!(huge.validate(), Err(Error::InvalidConfig { .. })));
        let nan_zero = ServoAxis {
            zero_deg: f64::NAN,
            ..ServoAxis::default()
        };
        assert_eq!(
            nan_zero.validate(),
            Err(Error::NonFinite {
                what: "servo zero_deg"
            })
        );
        assert_eq!(
            ServoAxis::default().joint_to_wire(Joint::Yaw, f64::NAN),
            Err(Error::NonFinite { what: "yaw" })
        );
        assert_eq!(Direction::from_sign(0), None);
        assert_eq!(Direction::from_sign(-1), Some(Direction::Reversed));
    }

    fn axis() -> impl Strategy<Value = ServoAxis> {
        (
            prop::bool::ANY,
            0.5f64..2.0,
            -30.0f64..30.0,
            -180.0f64..-60.0,
            60.0f64..180.0,
        )
            .prop_map(|(rev, scale, zero_deg, min_deg, max_deg)| ServoAxis {
                direction: if rev {
                    Direction::Reversed
                } else {
                    Direction::Normal
                },
                scale,
                zero_deg,
                min_deg,
                max_deg,
            })
    }

    proptest! {
        #[test]
        fn joint_wire_joint_within_half_a_tenth(s in axis(), t in 0.0f64..1.0) {
            let (lo, hi) = s.joint_range_deg().unwrap();
            let joint = lo + t * (hi - lo);
            let wire = s.joint_to_wire(Joint::Yaw, joint).unwrap();
            let back = s.wire_to_joint(wire).unwrap();
            // Half a 0.1° step in servo degrees, divided by the scale; a
            // whole step at a limit off the 0.1° grid (the nearest wire
            // value would lie beyond it, so the last one inside is used).
            let (lo_wire, hi_wire) = s.wire_limits();
            let at_limit = f64::from(wire) == lo_wire || f64::from(wire) == hi_wire;
            let step = if at_limit { 0.1 } else { 0.05 };
            prop_assert!((back - joint).abs() <= step / s.scale + 1e-9);
        }

        #[test]
        fn wire_joint_wire_is_identity(s in axis(), wire in -600i16..600) {
            let joint = s.wire_to_joint(wire).unwrap();
            prop_assert_eq!(s.joint_to_wire(Joint::Pitch, joint).unwrap(), wire);
        }
    }
}
