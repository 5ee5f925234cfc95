//! The G-code rows (issue 21): one line from the console to a planned
//! block on each actuator (grbl parser, G-code session and motion queue in
//! the sequencer core, then the actuator's planning stage with its
//! look-ahead replan), the dearest of a seeded sweep of G0/G1/G2/G3 lines
//! (firmware/bench-m4/src/gcode.rs). Goal: 2 000 lines/s within 25 % of
//! the CPU, i.e. 125 µs per line, ≤ 16 000 M4 instructions.

use super::budgets::{CLOCK_MHZ, CPI, Enforcement, Row};

/// Instructions per line the goal allows.
const LINE_INSTRUCTIONS: f64 = 16_000.0;

/// Why the goal is not met (measured: `gcode.line.*.core` is the core's
/// part of the dearest line; the rest is the actuator's stage; the causes
/// read from the code on that path).
const NOT_MET: &str = "f64 soft-float IK on every line: the core's reach check \
    (block_reachable: the end, an arc 17 points) is ~23 000-40 000 instructions for a \
    line, ~270 000-500 000 for an arc; the gimbal's stream tick aims 3 points per queued \
    block (joint_deg_per_mm); the stepper's piece count doubles with an IK + FK per piece \
    (pieces_for)";

/// Budget of one line: 16 000 instructions at the table's CPI and clock.
const fn line_budget() -> Option<(f64, &'static str, Enforcement)> {
    Some((
        LINE_INSTRUCTIONS * CPI / CLOCK_MHZ,
        "16 000 instructions: 2 000 lines/s within 25 % of the CPU",
        Enforcement::NotMet(NOT_MET),
    ))
}

/// The G-code rows.
pub const GCODE_ROWS: &[Row] = &[
    Row {
        id: "gcode.line.gimbal",
        what: "G-code line -> gimbal: core (parse, queue) + the next stream tick (look-ahead replan, servo aim); worst of a seeded sweep",
        unit: "line",
        budget: line_budget(),
    },
    Row {
        id: "gcode.line.gimbal.core",
        what: "the sequencer core's part of gcode.line.gimbal's dearest line",
        unit: "line",
        budget: None,
    },
    Row {
        id: "gcode.line.galvo",
        what: "G-code line -> galvo: core (parse, queue, stroke hand-over) + PathPlanner add onto three segments (replan); worst of a seeded sweep",
        unit: "line",
        budget: line_budget(),
    },
    Row {
        id: "gcode.line.galvo.core",
        what: "the sequencer core's part of gcode.line.galvo's dearest line",
        unit: "line",
        budget: None,
    },
    Row {
        id: "gcode.line.stepper",
        what: "G-code line -> stepper: core (parse, queue) + StepperMotion move_to and next_segment (mm -> steps, pieces into the planner, replan, one segment); worst of a seeded sweep",
        unit: "line",
        budget: line_budget(),
    },
    Row {
        id: "gcode.line.stepper.core",
        what: "the sequencer core's part of gcode.line.stepper's dearest line",
        unit: "line",
        budget: None,
    },
];
