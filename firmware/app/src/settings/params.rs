//! The parameter table: id, name, unit, range and storage of every
//! parameter, in ascending id order (the order of `params` and of the
//! saved record).
//!
//! Ids are stable (like grbl's `$N`): the saved record keys each value by
//! its parameter's id, so adding, removing or compiling out a parameter
//! never changes how the others are stored. An id is never changed or
//! reused; a new parameter takes a free id in its group:
//!
//! | ids     | group                                         |
//! |---------|-----------------------------------------------|
//! | 10–19   | gimbal geometry (`oq_cm` 10, `ol_cm` 11)      |
//! | 20–29   | grid and board (`grid.*` 20–24, `board.roll_deg` 25) |
//! | 30–39   | motion (`dwell_ms` 30, `servo.*` 31–32, `path.step_cm` 33) |
//! | 40–49   | yaw servo: 40 id, 41 dir, 42 scale, 43 zero_deg, 44 min_deg, 45 max_deg |
//! | 50–59   | pitch servo: the same, 50–55                  |
//! | 60–69   | laser (`laser.mode` 60)                        |
//! | 70–79   | error model x: `err.dx.c0..c5` 70–75          |
//! | 80–89   | error model y: `err.dy.c0..c5` 80–85          |
//! | 100–109 | galvo geometry (`d_mm` 100, `e_mm` 101)       |
//! | 110–119 | galvo DAC mapping (x scale, x offset, y scale, y offset: 110–113) |
//! | 120–129 | galvo drive (Kt, J, L, R, Umax, Ts: 120–125)  |
//! | 130–139 | galvo jump planner (130)                      |
//! | 140–149 | galvo laser delays (on 140, off 141)          |
//! | 150–159 | galvo marking (speed 150, acceleration 151)   |
//! | 160–168 | stepper drive: step angle, microsteps, speed, acceleration, junction, pulse, DIR setup, ENABLE, idle release (`settings/stepper.rs`) |
//! | 169–172 | stepper pan: dir, zero_deg, min_deg, max_deg  |
//! | 173–176 | stepper tilt: the same                        |
//! | 177–183 | stepper homing: seek, latch, pull-off speeds/distance; pan home_dir, home_deg; tilt the same |
//! | 190–199 | G-code: `$11` junction deviation 190 (`settings/gcode.rs`) |
//! | 200–209 | PELCO port: address 200, baud 201, motion timeout 202 (`settings/pelco.rs`) |
//! | 210–219 | laser controls: emission indicator lead 210 (`settings/controls.rs`) |
//! | 177–183 | stepper homing: seek, latch, pull-off; pan home_dir, home_deg; tilt the same |

use super::controls::CONTROLS_PARAMS;
use super::gcode::GCODE_PARAMS;
use super::pelco_params::PELCO_PARAMS;
use super::spec::COEF_HELP;
use super::spec::{ParamSpec, Precision, Slot, choice, count, err_coef, real};
use super::stepper_params::STEPPER_PARAMS;
use kinematics_core::error_model::COEF_LIMITS;

/// Smallest |galvo DAC scale|, codes/rad: 4096 codes over ±45° of mirror.
pub const MIN_CODES_PER_RAD: f64 = 1_000.0;
/// Largest |galvo DAC scale|, codes/rad: 4096 codes over ±1° of mirror.
pub const MAX_CODES_PER_RAD: f64 = 120_000.0;

/// The parameter table (also the order of `params` and of the saved record).
pub static PARAMS: &[ParamSpec] = &joined::<82, 1, 83>(
    joined::<79, 3, 82>(
        joined::<78, 1, 79>(joined::<54, 24, 78>(BASE, STEPPER_PARAMS), GCODE_PARAMS),
        PELCO_PARAMS,
    ),
    CONTROLS_PARAMS,
);

/// Every parameter of `a` then every one of `b` (the table is built from
/// pieces kept next to what they describe).
const fn joined<const A: usize, const B: usize, const N: usize>(
    a: [ParamSpec; A],
    b: [ParamSpec; B],
) -> [ParamSpec; N] {
    assert!(A + B == N && A > 0);
    let mut out = [a[0]; N];
    let mut i = 0;
    while i < N {
        out[i] = if i < A { a[i] } else { b[i - A] };
        i += 1;
    }
    out
}

/// Parameters 10–151: gimbal, grid, motion, servos, laser, error model,
/// galvo.
const BASE: [ParamSpec; 54] = [
    real!(
        10,
        "oq_cm",
        5.0,
        500.0,
        "gimbal centre to board distance OQ, cm",
        |s| s.oq_cm
    ),
    real!(11, "ol_cm", 0.0, 20.0, "laser axis offset OL, cm", |s| s
        .ol_cm),
    real!(20, "grid.pitch_cm", 0.1, 20.0, "grid pitch, cm", |s| s
        .grid_pitch_cm),
    count!(
        21,
        "grid.cols",
        2.0,
        40.0,
        "grid columns (even), cells",
        |s| s.grid_cols
    ),
    count!(22, "grid.rows", 2.0, 40.0, "grid rows (even), cells", |s| s
        .grid_rows),
    real!(
        23,
        "grid.x_offset_cm",
        -100.0,
        100.0,
        "board x offset of the grid origin, cm",
        |s| s.x_offset_cm
    ),
    real!(
        24,
        "grid.y_offset_cm",
        -100.0,
        100.0,
        "board y offset of the grid origin, cm",
        |s| s.y_offset_cm
    ),
    real!(
        25,
        "board.roll_deg",
        -10.0,
        10.0,
        "board rotation about global x, deg",
        |s| s.board_roll_deg
    ),
    real!(
        30,
        "dwell_ms",
        0.0,
        60_000.0,
        "dwell per point after arrival, ms",
        |s| s.dwell_ms
    ),
    real!(
        31,
        "servo.speed_deg_s",
        1.0,
        750.0,
        "servo travel speed, deg/s",
        |s| s.servo_speed_deg_s
    ),
    real!(
        32,
        "servo.deadband_deg",
        0.1,
        10.0,
        "arrival deadband, deg",
        |s| s.deadband_deg
    ),
    real!(
        33,
        "path.step_cm",
        0.01,
        5.0,
        "line/circle/rect interpolation step, cm",
        |s| s.path_step_cm
    ),
    count!(40, "yaw.id", 0.0, 253.0, "yaw servo bus id", |s| s.yaw.id),
    choice!(
        41,
        "yaw.dir",
        -1.0,
        1.0,
        "yaw direction, +1 or -1",
        Slot::Sign(|s| &mut s.yaw.direction)
    ),
    real!(
        42,
        "yaw.scale",
        0.5,
        2.0,
        "yaw servo deg per joint deg",
        |s| s.yaw.scale
    ),
    real!(
        43,
        "yaw.zero_deg",
        -90.0,
        90.0,
        "yaw servo angle at joint 0, deg",
        |s| s.yaw.zero_deg
    ),
    real!(
        44,
        "yaw.min_deg",
        -180.0,
        180.0,
        "yaw servo lower limit, deg",
        |s| s.yaw.min_deg
    ),
    real!(
        45,
        "yaw.max_deg",
        -180.0,
        180.0,
        "yaw servo upper limit, deg",
        |s| s.yaw.max_deg
    ),
    count!(50, "pitch.id", 0.0, 253.0, "pitch servo bus id", |s| s
        .pitch
        .id),
    choice!(
        51,
        "pitch.dir",
        -1.0,
        1.0,
        "pitch direction, +1 or -1",
        Slot::Sign(|s| &mut s.pitch.direction)
    ),
    real!(
        52,
        "pitch.scale",
        0.5,
        2.0,
        "pitch servo deg per joint deg",
        |s| s.pitch.scale
    ),
    real!(
        53,
        "pitch.zero_deg",
        -90.0,
        90.0,
        "pitch servo angle at joint 0, deg",
        |s| s.pitch.zero_deg
    ),
    real!(
        54,
        "pitch.min_deg",
        -180.0,
        180.0,
        "pitch servo lower limit, deg",
        |s| s.pitch.min_deg
    ),
    real!(
        55,
        "pitch.max_deg",
        -180.0,
        180.0,
        "pitch servo upper limit, deg",
        |s| s.pitch.max_deg
    ),
    choice!(
        60,
        "laser.mode",
        0.0,
        2.0,
        "0 auto, 1 dwell, 2 off",
        Slot::Laser
    ),
    err_coef!(70, "err.dx.c0", err_dx, 0),
    err_coef!(71, "err.dx.c1", err_dx, 1),
    err_coef!(72, "err.dx.c2", err_dx, 2),
    err_coef!(73, "err.dx.c3", err_dx, 3),
    err_coef!(74, "err.dx.c4", err_dx, 4),
    err_coef!(75, "err.dx.c5", err_dx, 5),
    err_coef!(80, "err.dy.c0", err_dy, 0),
    err_coef!(81, "err.dy.c1", err_dy, 1),
    err_coef!(82, "err.dy.c2", err_dy, 2),
    err_coef!(83, "err.dy.c3", err_dy, 3),
    err_coef!(84, "err.dy.c4", err_dy, 4),
    err_coef!(85, "err.dy.c5", err_dy, 5),
    real!(
        100,
        "galvo.d_mm",
        50.0,
        5000.0,
        Precision::F32,
        "galvo Y mirror to board distance d, mm",
        |s| s.galvo.d_mm
    ),
    real!(
        101,
        "galvo.e_mm",
        0.0,
        100.0,
        Precision::F32,
        "galvo mirror separation e, mm",
        |s| s.galvo.e_mm
    ),
    ParamSpec {
        id: 110,
        name: "galvo.x_codes_per_rad",
        min: -MAX_CODES_PER_RAD,
        max: MAX_CODES_PER_RAD,
        min_magnitude: MIN_CODES_PER_RAD,
        precision: Precision::F32,
        help: "galvo X DAC codes/rad, |v| >= 1000, sign = direction",
        slot: Slot::Real(|s| &mut s.galvo.x_codes_per_rad),
    },
    real!(
        111,
        "galvo.x_offset_code",
        0.0,
        4095.0,
        Precision::F32,
        "galvo X DAC code at angle 0",
        |s| s.galvo.x_offset_code
    ),
    ParamSpec {
        id: 112,
        name: "galvo.y_codes_per_rad",
        min: -MAX_CODES_PER_RAD,
        max: MAX_CODES_PER_RAD,
        min_magnitude: MIN_CODES_PER_RAD,
        precision: Precision::F32,
        help: "galvo Y DAC codes/rad, |v| >= 1000, sign = direction",
        slot: Slot::Real(|s| &mut s.galvo.y_codes_per_rad),
    },
    real!(
        113,
        "galvo.y_offset_code",
        0.0,
        4095.0,
        Precision::F32,
        "galvo Y DAC code at angle 0",
        |s| s.galvo.y_offset_code
    ),
    real!(
        120,
        "galvo.kt_nm_per_a",
        1e-4,
        1.0,
        "galvo motor torque constant Kt, N*m/A",
        |s| s.galvo.kt_nm_per_a
    ),
    real!(
        121,
        "galvo.j_kg_m2",
        1e-10,
        1e-4,
        "galvo rotor+mirror inertia J, kg*m^2",
        |s| s.galvo.j_kg_m2
    ),
    real!(
        122,
        "galvo.l_h",
        1e-6,
        0.1,
        "galvo coil inductance L, H",
        |s| s.galvo.l_h
    ),
    real!(
        123,
        "galvo.r_ohm",
        0.1,
        100.0,
        "galvo coil resistance R, ohm",
        |s| s.galvo.r_ohm
    ),
    real!(
        124,
        "galvo.u_max_v",
        1.0,
        100.0,
        "galvo drive voltage limit Umax, V",
        |s| s.galvo.u_max_v
    ),
    real!(
        125,
        "galvo.ts_us",
        5.0,
        1000.0,
        "galvo DAC sample period, us",
        |s| s.galvo.sample_period_us
    ),
    choice!(
        130,
        "galvo.planner",
        0.0,
        1.0,
        "galvo jump planner: 0 optimal, 1 seed",
        Slot::Planner
    ),
    real!(
        140,
        "galvo.laser_on_delay_us",
        0.0,
        10_000.0,
        "galvo hold before laser on after a jump, us",
        |s| s.galvo.laser_on_delay_us
    ),
    real!(
        141,
        "galvo.laser_off_delay_us",
        0.0,
        10_000.0,
        "galvo hold after laser off before a jump, us",
        |s| s.galvo.laser_off_delay_us
    ),
    real!(
        150,
        "galvo.mark_speed_mm_s",
        1.0,
        20_000.0,
        "galvo marking speed of paths, mm/s",
        |s| s.galvo.mark_speed_mm_s
    ),
    real!(
        151,
        "galvo.mark_accel_mm_s2",
        100.0,
        1.0e8,
        Precision::F32,
        "galvo marking acceleration, mm/s^2",
        |s| s.galvo.mark_accel_mm_s2
    ),
];

/// Finds a parameter by name (case-insensitive).
pub fn find_param(name: &str) -> Option<&'static ParamSpec> {
    PARAMS.iter().find(|p| p.name.eq_ignore_ascii_case(name))
}

/// Finds a parameter of `table` by id.
pub(crate) fn param_by_id(table: &[ParamSpec], id: u16) -> Option<&ParamSpec> {
    table.iter().find(|p| p.id == id)
}
