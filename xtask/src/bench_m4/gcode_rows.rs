//! The G-code rows (issue 21): one line from the console to a planned
//! block on each actuator (grbl parser, G-code session and motion queue in
//! the sequencer core, then the actuator's planning stage with its
//! look-ahead replan), the dearest of a seeded sweep of G0/G1/G2/G3 lines
//! (firmware/bench-m4/src/gcode.rs). Goal: 2 000 lines/s within 25 % of
//! the CPU, i.e. 125 µs per line, ≤ 16 000 M4 instructions.

use super::budgets::{CLOCK_MHZ, CPI, Enforcement, Row};

/// Instructions per line the goal allows.
const LINE_INSTRUCTIONS: f64 = 16_000.0;

/// Why the goal is not met, per actuator, with the goal proposed instead
/// (measured: `gcode.line.*.core` is the core's part of the dearest line,
/// the rest the actuator's stage; the causes read from the code on that
/// path and from the per-call rows `gimbal.ik_wire`, `path.add.*`). The
/// reach check no longer runs the IK for blocks inside the board rectangle
/// proven reachable (`sequencer/gcode/reach.rs`), the gimbal works out a
/// block's joint speed once, the stepper counts pieces in f32.
const NOT_MET_GIMBAL: &str = "a block's joint degrees per mm take three f64 aims \
    (error-model compensation, IK, servo mapping: ~28 000 instructions each) once, when \
    it is queued (the core's ~113 000 of the worst arc, ~30 000 of it parse and queue); \
    the next 20 ms stream tick ~115 000: one f64 aim for the servo point and the f64 \
    look-ahead replan over the queue (each block's end tangents, arcs through f64 \
    sin/cos; not profiled call by call). Proposed goal: 250 000 per line, i.e. 100 \
    lines/s (twice the stream's 50 Hz) within 20 % of the CPU";
/// See [`NOT_MET_GIMBAL`].
const NOT_MET_GALVO: &str = "the f64 path planner's add alone is 16 000 (line) to \
    23 000 (arc) instructions (rows path.add.*), the core's f64 parse, arc set-up and \
    queue ~30 000 for an arc: ~61 000 for an arc, ~27 000 the median line. Proposed \
    goal: 64 000 per line, i.e. 500 lines/s within 25 % of the CPU";
/// See [`NOT_MET_GIMBAL`].
const NOT_MET_STEPPER: &str = "every piece of a line goes through the f64 IK and a \
    planner push with an f64 replan, ~45 000 instructions, and one next_segment fills \
    the 16-block planner (15 pieces: ~690 000); the piece count runs in f32 (~160 000 \
    for a 64-piece arc) but a round whose deviation lies within 2 % of the tolerance is \
    decided piece by piece through the f64 IK and FK (~45 000 a piece: the worst line, \
    a 16-piece arc of r 5 mm, ~1 540 000); the median line ~58 000. Proposed goal: \
    64 000 per line plus 48 000 per piece cut (less needs an f32 IK for the piece ends \
    and an f32 stepper planner); enforced at 1 700 000, the worst line's 1 541 000 \
    with 10 % of room";

/// Budget of one line: 16 000 instructions at the table's CPI and clock,
/// not met for `why`; enforced at the goal restated for the actuator
/// (`ceiling_instructions`, the proposal in `why`).
const fn line_budget(
    why: &'static str,
    ceiling_instructions: f64,
) -> Option<(f64, &'static str, Enforcement)> {
    Some((
        LINE_INSTRUCTIONS * CPI / CLOCK_MHZ,
        "16 000 instructions: 2 000 lines/s within 25 % of the CPU",
        Enforcement::NotMet {
            why,
            ceiling_instructions,
        },
    ))
}

/// The G-code rows.
pub const GCODE_ROWS: &[Row] = &[
    Row {
        id: "gcode.line.gimbal",
        what: "G-code line -> gimbal: core (parse, queue) + the next stream tick (look-ahead replan, servo aim); worst of a seeded sweep",
        unit: "line",
        budget: line_budget(NOT_MET_GIMBAL, 250_000.0),
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
        budget: line_budget(NOT_MET_GALVO, 64_000.0),
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
        budget: line_budget(NOT_MET_STEPPER, 1_700_000.0),
    },
    Row {
        id: "gcode.line.stepper.core",
        what: "the sequencer core's part of gcode.line.stepper's dearest line",
        unit: "line",
        budget: None,
    },
];
