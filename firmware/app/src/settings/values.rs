//! The settings' values: [`Settings`] (every user parameter, SPEC
//! defaults) and its groups, and the rules between parameters.

use super::error::SettingsError;
use super::pelco::PelcoSettings;
use super::stepper::StepperSettings;

/// The laser controls' default emission indicator lead (parameter
/// `laser.emission_delay_s`), s.
pub(super) const DEFAULT_EMISSION_DELAY_S: f64 = 3.0;

/// One axis of the servo gimbal: wire mapping of SPEC §4.4.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisSettings {
    /// FashionStar bus id.
    pub id: u8,
    /// +1 or −1: servo angle sign relative to the joint angle.
    pub direction: i8,
    /// Servo degrees per joint degree (gear / calibration).
    pub scale: f64,
    /// Servo angle at joint angle 0, deg.
    pub zero_deg: f64,
    /// Lowest allowed servo angle, deg.
    pub min_deg: f64,
    /// Highest allowed servo angle, deg.
    pub max_deg: f64,
}

/// When the laser is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LaserMode {
    /// On while a pattern or goto is active (moves and dwells).
    Auto,
    /// On only while dwelling on a point.
    Dwell,
    /// Forced off.
    Off,
}

impl LaserMode {
    /// Name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            LaserMode::Auto => "auto",
            LaserMode::Dwell => "dwell",
            LaserMode::Off => "off",
        }
    }

    pub(super) fn from_code(code: f64) -> Option<Self> {
        [LaserMode::Auto, LaserMode::Dwell, LaserMode::Off]
            .into_iter()
            .find(|m| m.code() == code)
    }

    pub(super) fn code(self) -> f64 {
        match self {
            LaserMode::Auto => 0.0,
            LaserMode::Dwell => 1.0,
            LaserMode::Off => 2.0,
        }
    }
}

/// Jump planner of the galvo.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum JumpPlanner {
    /// Time-optimal bang-bang jumps (default).
    Optimal,
    /// The patent's bisection method (minimum-energy input).
    Seed,
}

impl JumpPlanner {
    /// Name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            JumpPlanner::Optimal => "optimal",
            JumpPlanner::Seed => "seed",
        }
    }
}

/// The galvo scanner: geometry (SPEC §4.5), DAC mapping, mirror drive
/// (SPEC §6) and laser timing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GalvoSettings {
    /// Y mirror to board distance d, mm.
    pub d_mm: f64,
    /// Mirror separation e, mm.
    pub e_mm: f64,
    /// X DAC codes per radian of mechanical mirror angle (sign = direction).
    pub x_codes_per_rad: f64,
    /// X DAC code at mirror angle 0.
    pub x_offset_code: f64,
    /// Y DAC codes per radian.
    pub y_codes_per_rad: f64,
    /// Y DAC code at mirror angle 0.
    pub y_offset_code: f64,
    /// Motor torque constant Kt, N·m/A.
    pub kt_nm_per_a: f64,
    /// Rotor + mirror inertia J, kg·m².
    pub j_kg_m2: f64,
    /// Coil inductance L, H.
    pub l_h: f64,
    /// Coil resistance R, Ω.
    pub r_ohm: f64,
    /// Drive voltage limit Umax, V.
    pub u_max_v: f64,
    /// DAC sample period, µs.
    pub sample_period_us: f64,
    /// Jump planner.
    pub planner: JumpPlanner,
    /// Hold after a jump lands before the laser turns on, µs.
    pub laser_on_delay_us: f64,
    /// Hold after the laser turns off before the next jump, µs.
    pub laser_off_delay_us: f64,
    /// Marking speed of paths, mm/s.
    pub mark_speed_mm_s: f64,
    /// Marking acceleration of paths (and braking on stop), mm/s².
    pub mark_accel_mm_s2: f64,
}

impl Default for GalvoSettings {
    /// SPEC defaults: d 400 mm, e 10 mm, ±12.5° over the 12-bit DAC, the
    /// reference galvo drive, 100 kHz, time-optimal jumps, 100 µs delays.
    fn default() -> Self {
        let dac = kinematics_core::DacAxis::<f64>::default();
        let geometry = kinematics_core::GalvoGeometry::<f64>::default();
        let drive = galvo_planner::RigidParams::REFERENCE;
        Self {
            d_mm: geometry.d_mm,
            e_mm: geometry.e_mm,
            x_codes_per_rad: dac.codes_per_rad,
            x_offset_code: dac.offset_code,
            y_codes_per_rad: dac.codes_per_rad,
            y_offset_code: dac.offset_code,
            kt_nm_per_a: drive.kt_nm_per_a,
            j_kg_m2: drive.j_kg_m2,
            l_h: drive.l_h,
            r_ohm: drive.r_ohm,
            u_max_v: drive.u_max_v,
            sample_period_us: 10.0,
            planner: JumpPlanner::Optimal,
            laser_on_delay_us: 100.0,
            laser_off_delay_us: 100.0,
            mark_speed_mm_s: 1000.0,
            mark_accel_mm_s2: 1.0e5,
        }
    }
}

/// Every user parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Gimbal centre to board distance OQ, cm.
    pub oq_cm: f64,
    /// Laser axis offset OL, cm.
    pub ol_cm: f64,
    /// Grid pitch, cm.
    pub grid_pitch_cm: f64,
    /// Grid columns (cells); indices run −cols/2..=cols/2.
    pub grid_cols: u8,
    /// Grid rows (cells); indices run −rows/2..=rows/2.
    pub grid_rows: u8,
    /// Board x offset of the grid origin, cm.
    pub x_offset_cm: f64,
    /// Board y offset of the grid origin, cm.
    pub y_offset_cm: f64,
    /// Board rotation about the global x axis (mounting error), deg.
    pub board_roll_deg: f64,
    /// Dwell on each point after arrival, ms.
    pub dwell_ms: f64,
    /// Servo travel speed used to derive move intervals, deg/s.
    pub servo_speed_deg_s: f64,
    /// Arrival deadband, deg.
    pub deadband_deg: f64,
    /// Step of the line / circle / rect interpolation, cm.
    pub path_step_cm: f64,
    /// Yaw servo mapping.
    pub yaw: AxisSettings,
    /// Pitch servo mapping.
    pub pitch: AxisSettings,
    /// Laser mode.
    pub laser_mode: LaserMode,
    /// Error-model coefficients for x (1, x, y, x², xy, y²), mm.
    pub err_dx: [f64; 6],
    /// Error-model coefficients for y, mm.
    pub err_dy: [f64; 6],
    /// The galvo scanner.
    pub galvo: GalvoSettings,
    /// The stepper pan/tilt.
    pub stepper: StepperSettings,
    /// G-code's junction deviation (grbl's `$11`), mm.
    pub gcode_junction_mm: f64,
    /// The PELCO port.
    pub pelco: PelcoSettings,
    /// The laser controls' emission indicator lead: on this long after
    /// `arm` before the laser may emit, s.
    pub emission_delay_s: f64,
}

impl Default for Settings {
    /// SPEC defaults (§4.1, §4.4, §4.6).
    fn default() -> Self {
        let axis = |id| AxisSettings {
            id,
            direction: 1,
            scale: 1.0,
            zero_deg: 0.0,
            min_deg: -135.0,
            max_deg: 135.0,
        };
        Self {
            oq_cm: 25.0,
            ol_cm: 5.4,
            grid_pitch_cm: 1.916,
            grid_cols: 12,
            grid_rows: 8,
            x_offset_cm: 0.0,
            y_offset_cm: 0.0,
            board_roll_deg: 0.0,
            dwell_ms: 1000.0,
            servo_speed_deg_s: 200.0,
            deadband_deg: 0.5,
            path_step_cm: 0.2,
            yaw: axis(0),
            pitch: axis(1),
            laser_mode: LaserMode::Auto,
            err_dx: [0.0; 6],
            err_dy: [0.0; 6],
            galvo: GalvoSettings::default(),
            stepper: StepperSettings::default(),
            gcode_junction_mm: 0.01,
            pelco: PelcoSettings::default(),
            emission_delay_s: DEFAULT_EMISSION_DELAY_S,
        }
    }
}

impl Settings {
    /// Rules between parameters.
    pub fn validate(&self) -> Result<(), SettingsError> {
        if !self.grid_cols.is_multiple_of(2) || !self.grid_rows.is_multiple_of(2) {
            return Err(SettingsError::Rejected(
                "grid.cols and grid.rows must be even",
            ));
        }
        if self.ol_cm >= self.oq_cm {
            return Err(SettingsError::Rejected("ol_cm must be smaller than oq_cm"));
        }
        for axis in [&self.yaw, &self.pitch] {
            if axis.min_deg >= axis.max_deg {
                return Err(SettingsError::Rejected(
                    "servo min_deg must be below max_deg",
                ));
            }
        }
        if self.yaw.id == self.pitch.id {
            return Err(SettingsError::Rejected("yaw.id and pitch.id must differ"));
        }
        self.stepper.validate()
    }
}
