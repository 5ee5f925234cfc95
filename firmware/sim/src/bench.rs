//! How the simulated bench is built and set: what a user sets with the
//! stepper drivers' DIP switches and gets wrong with a screwdriver (a
//! board mounted rolled or at another distance, a servo horn one spline
//! off zero). The firmware does not know any of it; its settings describe
//! the bench it *thinks* it drives, so a mismatch shows as it would on a
//! real bench: wrong travel, a tilted grid.

use kinematics_core::stepper::StepperAxis;

use crate::stepper::MotorLimits;
use crate::world::SimOptions;

/// Full step of the simulated stepper motors, degrees (1.8° NEMA-17).
pub const MOTOR_FULL_STEP_DEG: f64 = 1.8;
/// The microsteps the simulated motor model's default limits are stated at.
const MOTOR_LIMITS_MICROSTEPS: u32 = 32;
/// Microstep settings a TB6600-class driver's switches offer.
pub const DRIVER_MICROSTEPS: [u32; 9] = [1, 2, 4, 8, 16, 32, 64, 128, 256];

/// The simulated bench's build and switch settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BenchBuild {
    /// The stepper drivers' microstep switches (both drivers), microsteps
    /// per full step.
    pub stepper_microsteps: u32,
    /// The board's roll about the beam axis through the gimbal, degrees.
    pub board_roll_deg: f64,
    /// Where the yaw (pan) servo's zero really is, joint degrees.
    pub yaw_zero_deg: f64,
    /// Where the pitch (tilt) servo's zero really is, joint degrees.
    pub pitch_zero_deg: f64,
    /// The real distance OQ from the gimbal centre to the board, cm
    /// (`None`: the SPEC's 25 cm).
    pub board_distance_cm: Option<f64>,
}

impl Default for BenchBuild {
    /// The SPEC's bench, built exactly: drivers at 32 microsteps.
    fn default() -> Self {
        Self {
            stepper_microsteps: MOTOR_LIMITS_MICROSTEPS,
            board_roll_deg: 0.0,
            yaw_zero_deg: 0.0,
            pitch_zero_deg: 0.0,
            board_distance_cm: None,
        }
    }
}

/// Largest build error the simulator takes for a roll or a zero, degrees.
const MAX_BUILD_ERROR_DEG: f64 = 10.0;
/// Board distances the simulator takes, cm.
const BOARD_DISTANCE_CM: core::ops::RangeInclusive<f64> = 5.0..=500.0;

impl BenchBuild {
    /// Checks the values: a driver's microstep setting, build errors within
    /// ±10°, a board 5–500 cm away.
    pub fn validate(&self) -> Result<(), String> {
        if !DRIVER_MICROSTEPS.contains(&self.stepper_microsteps) {
            return Err(format!(
                "stepper microsteps {} is not a driver setting ({DRIVER_MICROSTEPS:?})",
                self.stepper_microsteps
            ));
        }
        for (name, deg) in [
            ("board roll", self.board_roll_deg),
            ("yaw zero", self.yaw_zero_deg),
            ("pitch zero", self.pitch_zero_deg),
        ] {
            if !deg.is_finite() || deg.abs() > MAX_BUILD_ERROR_DEG {
                return Err(format!("{name} {deg}° is outside ±{MAX_BUILD_ERROR_DEG}°"));
            }
        }
        if let Some(cm) = self.board_distance_cm
            && !BOARD_DISTANCE_CM.contains(&cm)
        {
            return Err(format!(
                "board distance {cm} cm is outside {}–{} cm",
                BOARD_DISTANCE_CM.start(),
                BOARD_DISTANCE_CM.end()
            ));
        }
        Ok(())
    }

    /// `options` with this bench: the servo gimbal's and the stepper
    /// pan/tilt's true geometry (same board), the stepper drivers' true
    /// step angle, and the motor model at that microstep setting (the same
    /// motor: torque, rate and acceleration scaled to the finer steps).
    pub fn apply(&self, options: SimOptions) -> Result<SimOptions, String> {
        self.validate()?;
        let mut options = options;
        for geometry in [
            &mut options.physical.gimbal.geometry,
            &mut options.stepper_geometry.gimbal.geometry,
        ] {
            geometry.frame.pose.roll_deg = self.board_roll_deg;
            if let Some(cm) = self.board_distance_cm {
                geometry.frame.oq_cm = cm;
            }
        }
        let gimbal = &mut options.physical.gimbal.geometry;
        gimbal.yaw.zero_deg = self.yaw_zero_deg;
        gimbal.pitch.zero_deg = self.pitch_zero_deg;
        options.stepper_geometry.zero.yaw_deg = self.yaw_zero_deg;
        options.stepper_geometry.zero.pitch_deg = self.pitch_zero_deg;
        let axis = StepperAxis::from_motor(MOTOR_FULL_STEP_DEG, self.microsteps_u16())
            .map_err(|e| format!("stepper axis: {e:?}"))?;
        options.stepper_geometry.axes = [
            StepperAxis {
                direction: options.stepper_geometry.axes[0].direction,
                ..axis
            },
            StepperAxis {
                direction: options.stepper_geometry.axes[1].direction,
                ..axis
            },
        ];
        options.stepper_motor = motor_at(self.stepper_microsteps);
        Ok(options)
    }

    fn microsteps_u16(&self) -> u16 {
        u16::try_from(self.stepper_microsteps).unwrap_or(u16::MAX)
    }

    /// A hint for the run summary when the firmware was told another
    /// microstep setting than the drivers have (`firmware_microsteps`: the
    /// value of `stepper.microsteps` it ran with).
    pub fn microstep_hint(&self, firmware_microsteps: u32) -> Option<String> {
        (firmware_microsteps != self.stepper_microsteps).then(|| {
            format!(
                "the drivers' switches are at {} microsteps but the firmware's stepper.microsteps is {}: \
                 every stepper move travels {:.3}× the commanded angle \
                 (set stepper.microsteps {} to match the drivers)",
                self.stepper_microsteps,
                firmware_microsteps,
                f64::from(firmware_microsteps) / f64::from(self.stepper_microsteps),
                self.stepper_microsteps
            )
        })
    }
}

/// The default motor's limits at `microsteps` per full step.
fn motor_at(microsteps: u32) -> MotorLimits {
    let motor = MotorLimits::default();
    let scale = f64::from(microsteps) / f64::from(MOTOR_LIMITS_MICROSTEPS);
    MotorLimits {
        microsteps,
        max_rate_steps_per_s: motor.max_rate_steps_per_s * scale,
        max_accel_steps_per_s2: motor.max_accel_steps_per_s2 * scale,
    }
}

/// The `stepper.microsteps` value a script sets last (the firmware's
/// default, 32, when it sets none): what the firmware ran with, for the
/// mismatch hint.
pub fn microsteps_set_by(lines: &[String]) -> u32 {
    lines
        .iter()
        .filter_map(|l| l.trim().strip_prefix("set stepper.microsteps "))
        .filter_map(|v| v.trim().parse::<f64>().ok())
        .filter(|v| v.is_finite() && *v >= 1.0 && v.fract() == 0.0 && *v <= f64::from(u32::MAX))
        .map(|v| v as u32)
        .next_back()
        .unwrap_or(MOTOR_LIMITS_MICROSTEPS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_bench_is_the_default_options() {
        let options = BenchBuild::default().apply(SimOptions::default()).unwrap();
        let default = SimOptions::default();
        assert_eq!(options.physical, default.physical);
        assert_eq!(options.stepper_geometry, default.stepper_geometry);
        assert_eq!(options.stepper_motor, default.stepper_motor);
    }

    #[test]
    fn microsteps_set_the_true_step_angle_and_scale_the_motor() {
        let bench = BenchBuild {
            stepper_microsteps: 256,
            ..BenchBuild::default()
        };
        let options = bench.apply(SimOptions::default()).unwrap();
        for axis in options.stepper_geometry.axes {
            assert!((axis.deg_per_step - 1.8 / 256.0).abs() < 1e-15);
        }
        assert_eq!(options.stepper_motor.microsteps, 256);
        assert_eq!(options.stepper_motor.max_rate_steps_per_s, 64_000.0 * 8.0);
    }

    #[test]
    fn build_errors_reach_both_pan_tilts() {
        let bench = BenchBuild {
            board_roll_deg: 1.0,
            yaw_zero_deg: 0.8,
            pitch_zero_deg: -0.3,
            board_distance_cm: Some(30.0),
            ..BenchBuild::default()
        };
        let o = bench.apply(SimOptions::default()).unwrap();
        let g = o.physical.gimbal.geometry;
        assert_eq!(g.frame.pose.roll_deg, 1.0);
        assert_eq!(g.frame.oq_cm, 30.0);
        assert_eq!((g.yaw.zero_deg, g.pitch.zero_deg), (0.8, -0.3));
        let s = o.stepper_geometry;
        assert_eq!(s.gimbal.geometry.frame.pose.roll_deg, 1.0);
        assert_eq!(s.gimbal.geometry.frame.oq_cm, 30.0);
        assert_eq!((s.zero.yaw_deg, s.zero.pitch_deg), (0.8, -0.3));
    }

    #[test]
    fn nonsense_is_refused() {
        for bad in [
            BenchBuild {
                stepper_microsteps: 3,
                ..BenchBuild::default()
            },
            BenchBuild {
                board_roll_deg: f64::NAN,
                ..BenchBuild::default()
            },
            BenchBuild {
                yaw_zero_deg: 45.0,
                ..BenchBuild::default()
            },
            BenchBuild {
                board_distance_cm: Some(0.0),
                ..BenchBuild::default()
            },
        ] {
            assert!(bad.apply(SimOptions::default()).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn the_hint_names_the_mismatch_and_the_fix() {
        let bench = BenchBuild {
            stepper_microsteps: 256,
            ..BenchBuild::default()
        };
        assert_eq!(bench.microstep_hint(256), None);
        let hint = bench.microstep_hint(32).unwrap();
        assert!(
            hint.contains("0.125×") && hint.contains("set stepper.microsteps 256"),
            "{hint}"
        );
        let lines = vec![
            "target stepper".to_owned(),
            "set stepper.microsteps 256".to_owned(),
        ];
        assert_eq!(microsteps_set_by(&lines), 256);
        assert_eq!(microsteps_set_by(&[]), 32);
    }
}
