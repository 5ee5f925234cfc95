//! User parameters: one table gives every parameter's name, unit, range and
//! storage, so `set`, `get`, `params` and the saved record cannot disagree.
//!
//! Values are f64 in the unit in the parameter's name (cm, mm, deg, ms,
//! deg/s). Integer parameters (ids, counts, directions) are checked to be
//! whole numbers.

use core::fmt;

use crate::cli::error::CommandError;
use crate::cli::format::Shortest;

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

/// How a parameter's value is stored.
#[derive(Clone, Copy)]
enum Slot {
    Real(fn(&mut Settings) -> &mut f64),
    Count(fn(&mut Settings) -> &mut u8),
    Sign(fn(&mut Settings) -> &mut i8),
    Laser,
    // Only in builds with galvo output.
    #[cfg_attr(not(feature = "galvo"), allow(dead_code))]
    Planner,
}

/// Description of one parameter.
#[derive(Clone, Copy)]
pub struct ParamSpec {
    /// Name used by `set` / `get`.
    pub name: &'static str,
    /// Lowest accepted value.
    pub min: f64,
    /// Highest accepted value.
    pub max: f64,
    /// What it is, with unit.
    pub help: &'static str,
    slot: Slot,
}

macro_rules! real {
    ($name:literal, $min:expr, $max:expr, $help:literal, |$s:ident| $place:expr) => {
        ParamSpec {
            name: $name,
            min: $min,
            max: $max,
            help: $help,
            slot: Slot::Real(|$s| &mut $place),
        }
    };
}

macro_rules! err_coef {
    ($name:literal, $axis:ident, $i:literal) => {
        real!($name, -1e3, 1e3, "error-model coefficient, mm", |s| s.$axis
            [$i])
    };
}

/// The parameter table (also the order of `params` and of the saved record).
pub const PARAMS: &[ParamSpec] = &[
    real!(
        "oq_cm",
        5.0,
        500.0,
        "gimbal centre to board distance OQ, cm",
        |s| s.oq_cm
    ),
    real!("ol_cm", 0.0, 20.0, "laser axis offset OL, cm", |s| s.ol_cm),
    real!("grid.pitch_cm", 0.1, 20.0, "grid pitch, cm", |s| s
        .grid_pitch_cm),
    ParamSpec {
        name: "grid.cols",
        min: 2.0,
        max: 40.0,
        help: "grid columns (even), cells",
        slot: Slot::Count(|s| &mut s.grid_cols),
    },
    ParamSpec {
        name: "grid.rows",
        min: 2.0,
        max: 40.0,
        help: "grid rows (even), cells",
        slot: Slot::Count(|s| &mut s.grid_rows),
    },
    real!(
        "grid.x_offset_cm",
        -100.0,
        100.0,
        "board x offset of the grid origin, cm",
        |s| s.x_offset_cm
    ),
    real!(
        "grid.y_offset_cm",
        -100.0,
        100.0,
        "board y offset of the grid origin, cm",
        |s| s.y_offset_cm
    ),
    real!(
        "board.roll_deg",
        -10.0,
        10.0,
        "board rotation about global x, deg",
        |s| s.board_roll_deg
    ),
    real!(
        "dwell_ms",
        0.0,
        60_000.0,
        "dwell per point after arrival, ms",
        |s| s.dwell_ms
    ),
    real!(
        "servo.speed_deg_s",
        1.0,
        750.0,
        "servo travel speed, deg/s",
        |s| s.servo_speed_deg_s
    ),
    real!(
        "servo.deadband_deg",
        0.1,
        10.0,
        "arrival deadband, deg",
        |s| s.deadband_deg
    ),
    real!(
        "path.step_cm",
        0.01,
        5.0,
        "line/circle/rect interpolation step, cm",
        |s| s.path_step_cm
    ),
    ParamSpec {
        name: "yaw.id",
        min: 0.0,
        max: 253.0,
        help: "yaw servo bus id",
        slot: Slot::Count(|s| &mut s.yaw.id),
    },
    ParamSpec {
        name: "yaw.dir",
        min: -1.0,
        max: 1.0,
        help: "yaw direction, +1 or -1",
        slot: Slot::Sign(|s| &mut s.yaw.direction),
    },
    real!("yaw.scale", 0.5, 2.0, "yaw servo deg per joint deg", |s| s
        .yaw
        .scale),
    real!(
        "yaw.zero_deg",
        -90.0,
        90.0,
        "yaw servo angle at joint 0, deg",
        |s| s.yaw.zero_deg
    ),
    real!(
        "yaw.min_deg",
        -180.0,
        180.0,
        "yaw servo lower limit, deg",
        |s| s.yaw.min_deg
    ),
    real!(
        "yaw.max_deg",
        -180.0,
        180.0,
        "yaw servo upper limit, deg",
        |s| s.yaw.max_deg
    ),
    ParamSpec {
        name: "pitch.id",
        min: 0.0,
        max: 253.0,
        help: "pitch servo bus id",
        slot: Slot::Count(|s| &mut s.pitch.id),
    },
    ParamSpec {
        name: "pitch.dir",
        min: -1.0,
        max: 1.0,
        help: "pitch direction, +1 or -1",
        slot: Slot::Sign(|s| &mut s.pitch.direction),
    },
    real!(
        "pitch.scale",
        0.5,
        2.0,
        "pitch servo deg per joint deg",
        |s| s.pitch.scale
    ),
    real!(
        "pitch.zero_deg",
        -90.0,
        90.0,
        "pitch servo angle at joint 0, deg",
        |s| s.pitch.zero_deg
    ),
    real!(
        "pitch.min_deg",
        -180.0,
        180.0,
        "pitch servo lower limit, deg",
        |s| s.pitch.min_deg
    ),
    real!(
        "pitch.max_deg",
        -180.0,
        180.0,
        "pitch servo upper limit, deg",
        |s| s.pitch.max_deg
    ),
    ParamSpec {
        name: "laser.mode",
        min: 0.0,
        max: 2.0,
        help: "0 auto, 1 dwell, 2 off",
        slot: Slot::Laser,
    },
    err_coef!("err.dx.c0", err_dx, 0),
    err_coef!("err.dx.c1", err_dx, 1),
    err_coef!("err.dx.c2", err_dx, 2),
    err_coef!("err.dx.c3", err_dx, 3),
    err_coef!("err.dx.c4", err_dx, 4),
    err_coef!("err.dx.c5", err_dx, 5),
    err_coef!("err.dy.c0", err_dy, 0),
    err_coef!("err.dy.c1", err_dy, 1),
    err_coef!("err.dy.c2", err_dy, 2),
    err_coef!("err.dy.c3", err_dy, 3),
    err_coef!("err.dy.c4", err_dy, 4),
    err_coef!("err.dy.c5", err_dy, 5),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.d_mm",
        50.0,
        5000.0,
        "galvo Y mirror to board distance d, mm",
        |s| s.galvo.d_mm
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.e_mm",
        0.0,
        100.0,
        "galvo mirror separation e, mm",
        |s| s.galvo.e_mm
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.x_codes_per_rad",
        -1e6,
        1e6,
        "galvo X DAC codes per rad (sign = direction)",
        |s| s.galvo.x_codes_per_rad
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.x_offset_code",
        0.0,
        4095.0,
        "galvo X DAC code at angle 0",
        |s| s.galvo.x_offset_code
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.y_codes_per_rad",
        -1e6,
        1e6,
        "galvo Y DAC codes per rad (sign = direction)",
        |s| s.galvo.y_codes_per_rad
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.y_offset_code",
        0.0,
        4095.0,
        "galvo Y DAC code at angle 0",
        |s| s.galvo.y_offset_code
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.kt_nm_per_a",
        1e-4,
        1.0,
        "galvo motor torque constant Kt, N*m/A",
        |s| s.galvo.kt_nm_per_a
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.j_kg_m2",
        1e-10,
        1e-4,
        "galvo rotor+mirror inertia J, kg*m^2",
        |s| s.galvo.j_kg_m2
    ),
    #[cfg(feature = "galvo")]
    real!("galvo.l_h", 1e-6, 0.1, "galvo coil inductance L, H", |s| s
        .galvo
        .l_h),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.r_ohm",
        0.1,
        100.0,
        "galvo coil resistance R, ohm",
        |s| s.galvo.r_ohm
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.u_max_v",
        1.0,
        100.0,
        "galvo drive voltage limit Umax, V",
        |s| s.galvo.u_max_v
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.ts_us",
        5.0,
        1000.0,
        "galvo DAC sample period, us",
        |s| s.galvo.sample_period_us
    ),
    #[cfg(feature = "galvo")]
    ParamSpec {
        name: "galvo.planner",
        min: 0.0,
        max: 1.0,
        help: "galvo jump planner: 0 optimal, 1 seed",
        slot: Slot::Planner,
    },
    #[cfg(feature = "galvo")]
    real!(
        "galvo.laser_on_delay_us",
        0.0,
        10_000.0,
        "galvo hold before laser on after a jump, us",
        |s| s.galvo.laser_on_delay_us
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.laser_off_delay_us",
        0.0,
        10_000.0,
        "galvo hold after laser off before a jump, us",
        |s| s.galvo.laser_off_delay_us
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.mark_speed_mm_s",
        1.0,
        20_000.0,
        "galvo marking speed of paths, mm/s",
        |s| s.galvo.mark_speed_mm_s
    ),
    #[cfg(feature = "galvo")]
    real!(
        "galvo.mark_accel_mm_s2",
        100.0,
        1.0e8,
        "galvo marking acceleration, mm/s^2",
        |s| s.galvo.mark_accel_mm_s2
    ),
];

/// Finds a parameter by name (case-insensitive).
pub fn find_param(name: &str) -> Option<&'static ParamSpec> {
    PARAMS.iter().find(|p| p.name.eq_ignore_ascii_case(name))
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
        if self.galvo.x_codes_per_rad == 0.0 || self.galvo.y_codes_per_rad == 0.0 {
            return Err(CommandError::Rejected("galvo codes_per_rad must not be 0"));
        }
        if self.yaw.id == self.pitch.id {
            return Err(CommandError::Rejected("yaw.id and pitch.id must differ"));
        }
        Ok(())
    }
}

/// Checks one value against its parameter's range and kind.
fn check_value(param: &ParamSpec, value: f64) -> Result<(), CommandError> {
    if !value.is_finite() || value < param.min || value > param.max {
        return Err(CommandError::OutOfRange {
            what: param.name,
            min: param.min,
            max: param.max,
        });
    }
    // In range, so the cast is exact for every whole value.
    let whole = (value as i64) as f64 == value;
    match param.slot {
        Slot::Real(_) => Ok(()),
        Slot::Count(_) if !whole => Err(CommandError::Rejected("value must be a whole number")),
        Slot::Sign(_) if value != 1.0 && value != -1.0 => {
            Err(CommandError::Rejected("direction must be 1 or -1"))
        }
        Slot::Planner if value != 0.0 && value != 1.0 => {
            Err(CommandError::Rejected("galvo.planner must be 0 or 1"))
        }
        Slot::Laser if LaserMode::from_code(value).is_none() => {
            Err(CommandError::Rejected("laser.mode must be 0, 1 or 2"))
        }
        _ => Ok(()),
    }
}

/// Format of `get`/`params` lines: `name = value  # help`.
pub struct ParamLine<'a>(pub &'a ParamSpec, pub f64);

impl fmt::Display for ParamLine<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} = {}  # {}",
            self.0.name,
            Shortest(self.1),
            self.0.help
        )
    }
}

/// Saved-record layout version; bump when [`PARAMS`] changes.
pub const RECORD_VERSION: u16 = 2;
/// Record magic.
const RECORD_MAGIC: [u8; 4] = *b"LPS1";
/// Bytes of a saved record: magic, version, count, values, CRC-32.
pub const RECORD_LEN: usize = 4 + 2 + 2 + 8 * PARAMS.len() + 4;

/// Why a saved record was not loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RecordError {
    /// Too short or wrong magic: nothing saved yet.
    Missing,
    /// Saved by another firmware version (layout differs).
    WrongVersion(u16),
    /// Checksum mismatch.
    Corrupt,
    /// A value is out of range.
    Invalid,
}

impl Settings {
    /// Serialises into the versioned, checksummed record.
    pub fn to_record(&self) -> [u8; RECORD_LEN] {
        let mut out = [0u8; RECORD_LEN];
        let mut w = Cursor {
            buf: &mut out,
            at: 0,
        };
        w.put(&RECORD_MAGIC);
        w.put(&RECORD_VERSION.to_le_bytes());
        w.put(&(PARAMS.len() as u16).to_le_bytes());
        for p in PARAMS {
            w.put(&self.get(p).to_le_bytes());
        }
        let body = RECORD_LEN - 4;
        let crc = crc32(out.get(..body).unwrap_or(&[]));
        if let Some(tail) = out.get_mut(body..) {
            tail.copy_from_slice(&crc.to_le_bytes());
        }
        out
    }

    /// Parses a record; every value goes through [`Settings::set`], so a
    /// record can never load values the command line would refuse.
    pub fn from_record(bytes: &[u8]) -> Result<Self, RecordError> {
        if bytes.len() < 8 || bytes.get(..4) != Some(&RECORD_MAGIC[..]) {
            return Err(RecordError::Missing);
        }
        let field = |at: usize| {
            u16::from_le_bytes([
                bytes.get(at).copied().unwrap_or(0),
                bytes.get(at + 1).copied().unwrap_or(0),
            ])
        };
        let (version, count) = (field(4), field(6));
        if version != RECORD_VERSION || usize::from(count) != PARAMS.len() {
            return Err(RecordError::WrongVersion(version));
        }
        let record = bytes.get(..RECORD_LEN).ok_or(RecordError::Corrupt)?;
        let (body, crc) = record.split_at(RECORD_LEN - 4);
        if crc32(body).to_le_bytes() != crc {
            return Err(RecordError::Corrupt);
        }
        let mut settings = Settings::default();
        for (i, p) in PARAMS.iter().enumerate() {
            let at = 8 + 8 * i;
            let mut le = [0u8; 8];
            le.copy_from_slice(body.get(at..at + 8).ok_or(RecordError::Corrupt)?);
            let value = f64::from_le_bytes(le);
            check_value(p, value).map_err(|_| RecordError::Invalid)?;
            settings.apply(p, value);
        }
        // Cross-parameter rules apply to the loaded set as a whole.
        settings.validate().map_err(|_| RecordError::Invalid)?;
        Ok(settings)
    }
}

struct Cursor<'a> {
    buf: &'a mut [u8],
    at: usize,
}

impl Cursor<'_> {
    fn put(&mut self, bytes: &[u8]) {
        if let Some(dst) = self.buf.get_mut(self.at..self.at + bytes.len()) {
            dst.copy_from_slice(bytes);
        }
        self.at += bytes.len();
    }
}

/// CRC-32 (IEEE 802.3, reflected, init and xor-out 0xFFFFFFFF).
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            let mask = (crc & 1).wrapping_neg();
            crc = (crc >> 1) ^ (0xEDB8_8320 & mask);
        }
    }
    !crc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_matches_the_standard_check_value() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

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

    #[test]
    fn record_round_trips_every_parameter() {
        let mut err_dy = [0.0; 6];
        err_dy[5] = -7.5e-6;
        let s = Settings {
            oq_cm: 31.25,
            err_dx: [0.1, -0.002, 0.003, 1e-5, -2e-5, 3e-6],
            err_dy,
            laser_mode: LaserMode::Dwell,
            pitch: AxisSettings {
                direction: -1,
                ..Settings::default().pitch
            },
            grid_cols: 10,
            ..Settings::default()
        };
        let record = s.to_record();
        assert_eq!(Settings::from_record(&record), Ok(s));
    }

    #[test]
    fn corrupt_old_or_missing_records_are_refused() {
        let record = Settings::default().to_record();
        assert_eq!(
            Settings::from_record(&[0xff; RECORD_LEN]),
            Err(RecordError::Missing)
        );
        assert_eq!(Settings::from_record(&[]), Err(RecordError::Missing));
        let mut flipped = record;
        flipped[20] ^= 0x10;
        assert_eq!(Settings::from_record(&flipped), Err(RecordError::Corrupt));
        let mut old = record;
        old[4] = 0;
        assert!(matches!(
            Settings::from_record(&old),
            Err(RecordError::WrongVersion(0))
        ));
        // A well-formed record with an out-of-range value (checksum fixed up).
        let bad = Settings {
            dwell_ms: -5.0,
            ..Settings::default()
        };
        assert_eq!(
            Settings::from_record(&bad.to_record()),
            Err(RecordError::Invalid)
        );
    }
}
