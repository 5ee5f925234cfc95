//! What the settings describe, as the geometry's objects: the calibrated
//! gimbal, the grid, the error model, the galvo mapping, and the
//! [`Aimer`] that holds them for a run (built once per change).

use kinematics_core as kc;
use kinematics_core::{DacAxis, ErrorModel, Galvo, GalvoGeometry, Gimbal, Grid};

use super::values::{AxisSettings, GalvoSettings, Settings};
use crate::domain::units::mm_from_cm;
use crate::domain::{AimModel, Aimer};

fn servo_axis(axis: &AxisSettings) -> kc::ServoAxis {
    kc::ServoAxis {
        direction: kc::Direction::from_sign(axis.direction).unwrap_or_default(),
        scale: axis.scale,
        zero_deg: axis.zero_deg,
        min_deg: axis.min_deg,
        max_deg: axis.max_deg,
    }
}

impl Settings {
    /// The board's extent, width and height (grbl's `$130`, `$131`: the
    /// grid's columns and rows times its pitch), mm.
    pub fn board_size_mm(&self) -> [f64; 2] {
        [
            mm_from_cm(self.grid_pitch_cm * f64::from(self.grid_cols)),
            mm_from_cm(self.grid_pitch_cm * f64::from(self.grid_rows)),
        ]
    }

    /// The calibrated gimbal these settings describe, aimed with `model`.
    pub fn gimbal(&self, model: AimModel) -> Gimbal {
        Gimbal {
            model: match model {
                AimModel::Exact => kc::GimbalModel::Exact,
                AimModel::Seed => kc::GimbalModel::Seed,
            },
            geometry: kc::GimbalGeometry {
                ol_cm: self.ol_cm,
                frame: kc::BoardFrame {
                    oq_cm: self.oq_cm,
                    x_offset_cm: 0.0,
                    y_offset_cm: 0.0,
                    pose: kc::BoardPose {
                        roll_deg: self.board_roll_deg,
                        ..kc::BoardPose::default()
                    },
                },
                yaw: servo_axis(&self.yaw),
                pitch: servo_axis(&self.pitch),
            },
        }
    }

    /// The grid (its offsets move the grid origin on the board).
    pub fn grid(&self) -> Grid {
        Grid {
            pitch_cm: self.grid_pitch_cm,
            cols: self.grid_cols,
            rows: self.grid_rows,
            x_offset_cm: self.x_offset_cm,
            y_offset_cm: self.y_offset_cm,
        }
    }

    /// The loaded error model (mm coefficients).
    pub fn error_model(&self) -> ErrorModel {
        ErrorModel::new(self.err_dx, self.err_dy)
    }

    /// The geometry a run aims with, the gimbal aimed with `model`.
    pub fn aimer(&self, model: AimModel) -> Aimer {
        Aimer::new(
            self.gimbal(model),
            self.error_model(),
            self.grid(),
            self.galvo.galvo().cast::<f64>(),
            self.path_step_cm,
        )
    }
}

impl GalvoSettings {
    /// The galvo these parameters describe: mirror geometry and DAC
    /// mappings (`f32`, as the loop runs it per sample).
    pub fn galvo(&self) -> Galvo<f32> {
        let dac = |codes_per_rad: f64, offset_code: f64| DacAxis {
            codes_per_rad: codes_per_rad as f32,
            offset_code: offset_code as f32,
        };
        Galvo {
            geometry: GalvoGeometry {
                d_mm: self.d_mm as f32,
                e_mm: self.e_mm as f32,
            },
            dac_x: dac(self.x_codes_per_rad, self.x_offset_code),
            dac_y: dac(self.y_codes_per_rad, self.y_offset_code),
        }
    }
}
