//! User parameters: one table gives every parameter's name, unit, range and
//! storage, so `set`, `get`, `params` and the saved record cannot disagree.
//!
//! Values are f64 in the unit in the parameter's name (cm, mm, deg, ms,
//! deg/s). Every parameter has a physically meaningful range (its
//! [`ParamSpec`]: `min..=max`, a smallest magnitude for signed scales, and
//! the precision it is used in); a value outside it, non-finite, or one
//! that would vanish or overflow in f32 where it is used as f32, is refused
//! and changes nothing. Integer parameters (ids, counts, directions) are
//! checked to be whole numbers.
//!
//! `params.rs` holds the table, `record.rs` the saved form, `store.rs` where
//! it is kept (two flash sectors, power-fail safe).

mod params;
mod record;
pub mod store;

pub use params::{
    MAX_CODES_PER_RAD, MIN_CODES_PER_RAD, PARAMS, ParamLine, ParamSpec, Precision, find_param,
};
pub use record::{RECORD_LEN, RECORD_VERSION, RecordError, crc32, intact_record_len};

#[cfg(test)]
use params::survives_f32;
use params::{Slot, check_value};

use crate::cli::error::CommandError;

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

    fn from_code(code: f64) -> Option<Self> {
        [LaserMode::Auto, LaserMode::Dwell, LaserMode::Off]
            .into_iter()
            .find(|m| m.code() == code)
    }

    fn code(self) -> f64 {
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
        }
    }
}

impl Settings {
    /// Current value of `param`.
    pub fn get(&self, param: &ParamSpec) -> f64 {
        let mut copy = *self;
        match param.slot {
            Slot::Real(place) => *place(&mut copy),
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
    /// cross-parameter rules; on error nothing changes.
    pub fn set(&mut self, param: &ParamSpec, value: f64) -> Result<(), CommandError> {
        check_value(param, value)?;
        let mut next = *self;
        next.apply(param, value);
        next.validate()?;
        *self = next;
        Ok(())
    }

    /// Stores an already checked value.
    fn apply(&mut self, param: &ParamSpec, value: f64) {
        match param.slot {
            Slot::Real(place) => *place(self) = value,
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

    /// Rules between parameters.
    pub fn validate(&self) -> Result<(), CommandError> {
        if !self.grid_cols.is_multiple_of(2) || !self.grid_rows.is_multiple_of(2) {
            return Err(CommandError::Rejected(
                "grid.cols and grid.rows must be even",
            ));
        }
        if self.ol_cm >= self.oq_cm {
            return Err(CommandError::Rejected("ol_cm must be smaller than oq_cm"));
        }
        for axis in [&self.yaw, &self.pitch] {
            if axis.min_deg >= axis.max_deg {
                return Err(CommandError::Rejected(
                    "servo min_deg must be below max_deg",
                ));
            }
        }
        if self.yaw.id == self.pitch.id {
            return Err(CommandError::Rejected("yaw.id and pitch.id must differ"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_defaults_are_in_range() {
        let d = Settings::default();
        for (i, p) in PARAMS.iter().enumerate() {
            assert!(
                PARAMS.iter().skip(i + 1).all(|q| q.name != p.name),
                "{}",
                p.name
            );
            let v = d.get(p);
            assert!(
                v >= p.min && v <= p.max,
                "{} default {v} out of range",
                p.name
            );
        }
        assert!(d.validate().is_ok());
    }

    #[test]
    fn set_checks_range_and_changes_nothing_on_error() {
        let mut s = Settings::default();
        let dwell = find_param("dwell_ms").unwrap();
        assert!(s.set(dwell, 250.0).is_ok());
        assert_eq!(s.dwell_ms, 250.0);
        let before = s;
        assert!(s.set(dwell, -1.0).is_err());
        assert!(s.set(dwell, f64::NAN).is_err());
        assert!(s.set(find_param("grid.cols").unwrap(), 13.0).is_err());
        assert!(s.set(find_param("grid.cols").unwrap(), 12.5).is_err());
        assert!(s.set(find_param("yaw.dir").unwrap(), 0.0).is_err());
        assert!(
            s.set(find_param("pitch.id").unwrap(), 0.0).is_err(),
            "ids must differ"
        );
        assert!(
            s.set(find_param("yaw.min_deg").unwrap(), 150.0).is_err(),
            "min < max"
        );
        assert_eq!(s, before);
        assert!(s.set(find_param("YAW.DIR").unwrap(), -1.0).is_ok());
        assert_eq!(s.yaw.direction, -1);
    }

    /// Values to try around a parameter's range: the bounds, the values
    /// just outside them, the values just inside its smallest magnitude,
    /// tiny and huge magnitudes, and non-finite values.
    fn probes(p: &ParamSpec) -> heapless::Vec<f64, 20> {
        let mut v: heapless::Vec<f64, 20> = heapless::Vec::new();
        let base = [
            p.min,
            p.max,
            p.min.next_down(),
            p.max.next_up(),
            1e-300,
            -1e-300,
            f64::MIN_POSITIVE,
            1e-40,
            1e39,
            -1e39,
            f64::MAX,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
        ];
        let m = p.min_magnitude;
        let near_zero = [m, -m, m.next_down(), -m.next_down()];
        for value in base.into_iter().chain(near_zero) {
            v.push(value).expect("20 probes fit");
        }
        v
    }

    /// What the firmware derives from the settings in the precision it uses
    /// them in must stay finite and non-degenerate.
    fn assert_usable(s: &Settings, what: &str) {
        for p in PARAMS {
            let v = s.get(p);
            assert!(v.is_finite(), "{what}: {} = {v}", p.name);
            if p.precision == Precision::F32 {
                assert!(survives_f32(v), "{what}: {} = {v} vanishes in f32", p.name);
            }
        }
        {
            let c = crate::sequencer::config_from(&s.galvo);
            for dac in [c.galvo.dac_x, c.galvo.dac_y] {
                assert!(
                    dac.codes_per_rad.is_finite() && dac.codes_per_rad.abs() >= 1_000.0,
                    "{what}: DAC scale {} in f32",
                    dac.codes_per_rad
                );
                assert!(dac.offset_code.is_finite());
            }
            assert!(c.galvo.geometry.d_mm.is_finite() && c.galvo.geometry.d_mm > 0.0);
            assert!(c.galvo.geometry.e_mm.is_finite());
            assert!(c.sample_period_s > 0.0 && c.sample_period_s.is_finite());
            assert!((c.mark_accel_mm_s2 as f32).is_normal());
        }
    }

    #[test]
    fn every_parameter_is_range_checked_in_the_precision_it_is_used_in() {
        let defaults = Settings::default();
        assert_usable(&defaults, "defaults");
        for p in PARAMS {
            assert!(
                p.min.is_finite() && p.max.is_finite() && p.min < p.max,
                "{}",
                p.name
            );
            assert!(!p.help.is_empty(), "{} documents its unit", p.name);
            let d = defaults.get(p);
            assert!(
                d >= p.min && d <= p.max && d.abs() >= p.min_magnitude,
                "{} default {d} out of range",
                p.name
            );
            assert!(check_value(p, d).is_ok(), "{} default refused", p.name);
            for value in probes(p) {
                let mut s = defaults;
                let in_range = value.is_finite()
                    && value >= p.min
                    && value <= p.max
                    && value.abs() >= p.min_magnitude;
                let result = s.set(p, value);
                if !in_range {
                    assert!(result.is_err(), "{} = {value} accepted", p.name);
                }
                match result {
                    Ok(()) => {
                        assert_eq!(s.get(p), value, "{} stores {value}", p.name);
                        assert_usable(&s, p.name);
                    }
                    Err(_) => assert_eq!(s, defaults, "refused {} = {value} changed", p.name),
                }
            }
        }
    }

    #[test]
    fn params_lines_show_the_range_and_fit_a_reply_line() {
        use core::fmt::Write as _;
        let d = Settings::default();
        // The default and in-range values with all 17 digits.
        for (p, value) in PARAMS.iter().flat_map(|p| {
            [
                (p, d.get(p)),
                (p, p.min * 0.987_654_321_098_765_4),
                (p, p.max * 0.123_456_789_012_345_67),
            ]
        }) {
            let mut line: heapless::String<256> = heapless::String::new();
            write!(line, "{}", ParamLine(p, value)).unwrap();
            assert!(
                line.len() <= crate::command::REPLY_LINE_LEN,
                "{} bytes: {line}",
                line.len()
            );
            assert!(line.ends_with(']') && line.contains(" # "), "{line}");
        }
    }

    #[test]
    fn a_galvo_scale_too_close_to_zero_is_refused() {
        for name in ["galvo.x_codes_per_rad", "galvo.y_codes_per_rad"] {
            let mut s = Settings::default();
            let before = s;
            let Some(p) = find_param(name) else {
                // Builds without galvo output have no galvo parameters.
                continue;
            };
            for value in [1e-300, -1e-300, 1e-45, 0.5, -999.0, 0.0] {
                assert!(s.set(p, value).is_err(), "{name} = {value}");
                assert_eq!(s, before);
            }
            assert!(s.set(p, -MIN_CODES_PER_RAD).is_ok());
            assert!(s.set(p, MAX_CODES_PER_RAD).is_ok());
        }
    }
}
