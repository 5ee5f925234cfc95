//! The safety invariant checker: reads a finished run's recording and
//! lists every breach of the laser-safety and protocol invariants
//! (SPEC §9, issue 9):
//!
//! * **(a) dark after a stop** ([`ViolationKind::LitAfterStop`]): every
//!   laser is dark from 1 ms after the sequencer processed a `stop`, the
//!   stop button, a servo fault, an actuator change or any other stop
//!   (except a pattern completing), and after the galvo loop learned of an
//!   underrun — until the next pattern or goto starts. Galvo samples the
//!   loop computed before that start must stay dark even when output
//!   later (a half already handed to the DAC, a replayed stale half).
//! * **(b) never lit while moving**: the galvo's laser is off whenever
//!   its DAC codes step by more than marking allows between two samples,
//!   i.e. during jumps ([`ViolationKind::LitGalvoJump`]); the gimbal's is
//!   off while it travels to the first point of a run, before the servo
//!   task confirmed the arrival ([`ViolationKind::LitTravel`]), and in
//!   `laser dwell` mode it is lit only after a confirmed arrival and while
//!   both servos truly are within the deadband of their targets
//!   ([`ViolationKind::LitWithoutArrival`]).
//! * **(c) one reply per line** ([`ViolationKind::Replies`]): each line
//!   the host sent gets exactly one `ok` / `error: …`, after its data
//!   lines, in the order the lines were sent; bracketed notices are not
//!   replies but must be whole lines.
//! * **(e) on the G-code path** ([`ViolationKind::OffPath`]) and **(f)
//!   motions end in time** ([`ViolationKind::LateMotion`]): see
//!   `conformance` for the rules and their stated tolerances.
//! * **(h) patterns on their figure** ([`ViolationKind::OffFigure`]):
//!   every lit sample of a `pattern`, `goto` or `grid` run lies within the
//!   spot's tolerance of the figure modelled from the transcript
//!   (`pattern_check.rs`, `pattern_model.rs`, `pattern_figure.rs`).
//! * **(g) the laser controls** ([`ViolationKind::LitWithoutControls`],
//!   on a board with them): no laser lit while the interlock is open or
//!   the key off, without the emission indicator on for the emission
//!   delay, or without a reset since the last opening (`controls.rs`).
//! * **(d) short task steps** ([`ViolationKind::LongStep`]): no poll of a
//!   firmware task takes more than 1 ms of thread CPU time (see
//!   [`crate::executor`] for what that measures).
//!
//! Inputs come through [`SafetyInputs`]: the recorded laser switching,
//! galvo DAC output, servo angles, sequencer events, the transcript and
//! the executor's step accounting. The galvo laser is read in one place,
//! [`galvo_stretches`]: the **effective** laser state of each sample.

mod conformance;
mod controls;
mod dark;
mod gcode_model;
mod gcode_piece;
mod inputs;
mod moving;
mod pattern_check;
mod pattern_figure;
mod pattern_model;
mod replies;
mod steps;
mod timeline;
mod violation;

use crate::world::SimReport;

use conformance::gcode_conformance;
pub use conformance::{DURATION_SLACK_S, RAPID_MIN_MM_S};
use controls::laser_controls_obeyed;
use dark::dark_after_stops;
pub use inputs::{GalvoStretch, SafetyInputs, galvo_stretches};
use moving::{galvo_jumps_dark, gimbal_dwell_mode, gimbal_travel_dark};
use pattern_check::patterns_on_their_figure;
use replies::one_reply_per_line;
use steps::short_steps;
pub use steps::{NOISE_RUNS, steady_steps};
use timeline::SettingsTimeline;
pub use violation::{DARK_WITHIN_US, MAX_STEP_NS, Violation, ViolationKind};

/// Violations of one kind listed at most (the rest are counted in one
/// more violation).
const MAX_LISTED_PER_KIND: usize = 50;

/// Checks every invariant of a finished run; empty when all hold.
pub fn check(report: &SimReport) -> Vec<Violation> {
    check_inputs(&SafetyInputs::from_report(report))
}

/// Checks every invariant on explicit inputs; violations in time order
/// within each kind, kinds in [`ViolationKind`] order.
pub fn check_inputs(inputs: &SafetyInputs<'_>) -> Vec<Violation> {
    let timeline = SettingsTimeline::from_transcript(inputs.transcript);
    let mut all = Vec::new();
    let mut add = |kind: ViolationKind, mut found: Vec<Violation>| {
        found.sort_by_key(|v| v.t_us);
        let extra = found.len().saturating_sub(MAX_LISTED_PER_KIND);
        if extra > 0 {
            let t_us = found[MAX_LISTED_PER_KIND].t_us;
            found.truncate(MAX_LISTED_PER_KIND);
            found.push(Violation {
                kind,
                t_us,
                detail: format!("… and {extra} more of this kind"),
            });
        }
        all.extend(found);
    };
    add(ViolationKind::LitAfterStop, dark_after_stops(inputs));
    add(
        ViolationKind::LitGalvoJump,
        galvo_jumps_dark(inputs, &timeline),
    );
    add(ViolationKind::LitTravel, gimbal_travel_dark(inputs));
    add(
        ViolationKind::LitWithoutArrival,
        gimbal_dwell_mode(inputs, &timeline),
    );
    add(
        ViolationKind::Replies,
        one_reply_per_line(inputs.transcript),
    );
    add(ViolationKind::LongStep, short_steps(inputs.task_steps));
    let (off_path, late) = gcode_conformance(inputs);
    add(ViolationKind::OffPath, off_path);
    add(ViolationKind::LateMotion, late);
    add(
        ViolationKind::LitWithoutControls,
        laser_controls_obeyed(inputs, &timeline),
    );
    add(ViolationKind::OffFigure, patterns_on_their_figure(inputs));
    all
}

/// A one-line summary per kind plus every listed violation, for
/// `cargo xtask sim --check-safety` and test failures.
pub fn report_text(violations: &[Violation]) -> String {
    if violations.is_empty() {
        return "safety: every invariant holds\n".to_owned();
    }
    let mut out = format!("safety: {} violation(s)\n", violations.len());
    for v in violations {
        out.push_str(&format!("  {v}\n"));
    }
    out
}

#[cfg(test)]
mod tests;
