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
//!   [`conformance`] for the rules and their stated tolerances.
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
mod moving;
mod pattern_check;
mod pattern_figure;
mod pattern_model;
mod replies;
mod steps;
mod timeline;

use std::fmt;

use crate::controls::ControlsRecord;
use crate::dac::DacRecording;
use crate::executor::{LONG_STEP_NS, TaskSteps};
use crate::physics::PhysicalGalvo;
use crate::recorder::{EventRecord, ServoSample, SpotSample};
use crate::usb_host::Transcript;
use crate::world::SimReport;

use conformance::gcode_conformance;
pub use conformance::{DURATION_SLACK_S, RAPID_MIN_MM_S};
use controls::laser_controls_obeyed;
use dark::dark_after_stops;
use moving::{galvo_jumps_dark, gimbal_dwell_mode, gimbal_travel_dark};
use pattern_check::patterns_on_their_figure;
use replies::one_reply_per_line;
use steps::short_steps;
pub use steps::{NOISE_RUNS, steady_steps};
use timeline::SettingsTimeline;

/// Time after a stop (fault, button, underrun, …) within which every
/// laser must be dark, µs.
pub const DARK_WITHIN_US: u64 = 1_000;

/// Longest firmware task step (poll), ns of CPU time.
pub const MAX_STEP_NS: u64 = LONG_STEP_NS;

/// Stop reasons after which a laser may stay lit: a pattern that
/// completed has its last laser-off delay in the DAC's buffer already.
const STOPS_THAT_ARE_NOT_SHUTDOWNS: &[&str] = &["pattern complete"];

/// Violations of one kind listed at most (the rest are counted in one
/// more violation).
const MAX_LISTED_PER_KIND: usize = 50;

/// Which invariant was broken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ViolationKind {
    /// (a) A laser lit more than 1 ms after a stop, fault, button press or
    /// underrun was processed.
    LitAfterStop,
    /// (b) The galvo laser lit while the mirrors jumped.
    LitGalvoJump,
    /// (b) The gimbal laser lit while travelling to a run's first point.
    LitTravel,
    /// (b) In `laser dwell` mode the gimbal laser lit without a confirmed
    /// arrival, or while a servo was truly outside the deadband.
    LitWithoutArrival,
    /// (c) A line without exactly one closing reply, a reply without a
    /// line, or a cut/glued line.
    Replies,
    /// (d) A firmware task step longer than 1 ms of CPU time.
    LongStep,
    /// (e) A lit G-code sample off the commanded path.
    OffPath,
    /// (f) A G-code motion not ended within its bound.
    LateMotion,
    /// (g) A laser lit while the interlock was open or the key off, before
    /// the emission indicator's delay, or without a reset since.
    LitWithoutControls,
    /// (h) A lit sample of a `pattern`, `goto` or `grid` run off its
    /// figure.
    OffFigure,
}

impl ViolationKind {
    /// Short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            ViolationKind::LitAfterStop => "lit-after-stop",
            ViolationKind::LitGalvoJump => "lit-galvo-jump",
            ViolationKind::LitTravel => "lit-travel",
            ViolationKind::LitWithoutArrival => "lit-without-arrival",
            ViolationKind::Replies => "replies",
            ViolationKind::LongStep => "long-step",
            ViolationKind::OffPath => "off-path",
            ViolationKind::LateMotion => "late-motion",
            ViolationKind::LitWithoutControls => "lit-without-controls",
            ViolationKind::OffFigure => "off-figure",
        }
    }
}

/// One breach of an invariant.
#[derive(Debug, Clone, PartialEq)]
pub struct Violation {
    /// Which invariant.
    pub kind: ViolationKind,
    /// Simulated time where it starts, µs.
    pub t_us: u64,
    /// What happened, for people.
    pub detail: String,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:>11.3} ms  {:<19}  {}",
            self.t_us as f64 / 1000.0,
            self.kind.name(),
            self.detail
        )
    }
}

/// A stretch of equal galvo DAC samples, one half buffer at most, as the
/// checker sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GalvoStretch {
    /// Output time of its first sample, ns.
    pub start_ns: u64,
    /// Sample period, ns.
    pub period_ns: u64,
    /// Samples.
    pub count: u64,
    /// X mirror DAC code.
    pub x_code: u16,
    /// Y mirror DAC code.
    pub y_code: u16,
    /// Effective laser state: what the beam does.
    pub laser: bool,
    /// When the galvo loop computed these samples, ns.
    pub computed_ns: u64,
}

impl GalvoStretch {
    /// Output time of its last sample, ns.
    pub fn last_ns(&self) -> u64 {
        self.start_ns + self.count.saturating_sub(1) * self.period_ns
    }
}

/// The galvo output as stretches of equal samples split at half-buffer
/// boundaries, in output order. This is the one place the checker reads
/// the galvo laser: the recorded laser column is the effective one (when
/// the simulator records a master laser gate, AND it in here).
pub fn galvo_stretches(dac: &DacRecording) -> Vec<GalvoStretch> {
    let halves = &dac.halves;
    let mut out = Vec::new();
    let mut half = 0usize;
    let mut k = 0usize;
    for (start_ns, period_ns, count, sample) in dac.runs() {
        let mut first = k;
        let end = k + count as usize;
        while first < end {
            while half + 1 < halves.len() && halves[half + 1].first_sample <= first {
                half += 1;
            }
            let half_end = halves.get(half + 1).map_or(usize::MAX, |h| h.first_sample);
            let last = end.min(half_end);
            out.push(GalvoStretch {
                start_ns: start_ns + (first - k) as u64 * period_ns,
                period_ns,
                count: (last - first) as u64,
                x_code: sample.x_code,
                y_code: sample.y_code,
                laser: sample.laser,
                computed_ns: halves.get(half).map_or(0, |h| h.computed_ns),
            });
            first = last;
        }
        k = end;
    }
    out
}

/// What the checker reads: borrowed from a [`SimReport`].
#[derive(Debug, Clone)]
pub struct SafetyInputs<'a> {
    /// Gimbal laser switching: (t µs, on), in order.
    pub gimbal_laser: &'a [(u64, bool)],
    /// Galvo output (effective laser).
    pub galvo: Vec<GalvoStretch>,
    /// When the galvo loop learned of each underrun, ns.
    pub underruns_ns: &'a [u64],
    /// Sequencer events, in processing order.
    pub events: &'a [EventRecord],
    /// Servo angles and targets.
    pub servos: &'a [ServoSample],
    /// The gimbal's or stepper's spot on the board.
    pub spot: &'a [SpotSample],
    /// The terminal transcript.
    pub transcript: &'a Transcript,
    /// Step accounting of every task.
    pub task_steps: &'a [TaskSteps],
    /// The true galvo (DAC codes → board).
    pub galvo_physics: PhysicalGalvo,
    /// Simulated time at the end of the run, µs.
    pub end_us: u64,
    /// The laser controls' inputs and indicator (`None`: the board has
    /// none).
    pub controls: Option<&'a ControlsRecord>,
}

impl<'a> SafetyInputs<'a> {
    /// The inputs of a finished run.
    pub fn from_report(report: &'a SimReport) -> Self {
        Self {
            gimbal_laser: &report.recording.laser_events,
            galvo: galvo_stretches(&report.dac),
            underruns_ns: &report.dac.underrun_detected_ns,
            events: &report.recording.events,
            servos: &report.recording.servos,
            spot: &report.recording.spot,
            transcript: &report.transcript,
            task_steps: &report.task_steps,
            galvo_physics: PhysicalGalvo::default(),
            end_us: report.end_time_us,
            controls: report.laser_controls.as_ref(),
        }
    }
}

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
