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
//! * **(d) short task steps** ([`ViolationKind::LongStep`]): no poll of a
//!   firmware task takes more than 1 ms of thread CPU time (see
//!   [`crate::executor`] for what that measures).
//!
//! Inputs come through [`SafetyInputs`]: the recorded laser switching,
//! galvo DAC output, servo angles, sequencer events, the transcript and
//! the executor's step accounting. The galvo laser is read in one place,
//! [`galvo_stretches`]: the **effective** laser state of each sample.

use std::collections::VecDeque;
use std::fmt;

use laser_app::cli::parse::parse_line;
use laser_app::command::Command;
use laser_app::settings::{LaserMode, Settings};

use crate::dac::DacRecording;
use crate::executor::{LONG_STEP_NS, TaskKind, TaskSteps};
use crate::physics::PhysicalGalvo;
use crate::recorder::{EventRecord, SequencerEvent, ServoSample};
use crate::usb_host::Transcript;
use crate::world::SimReport;

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
    /// The terminal transcript.
    pub transcript: &'a Transcript,
    /// Step accounting of every task.
    pub task_steps: &'a [TaskSteps],
    /// The true galvo (DAC codes → board).
    pub galvo_physics: PhysicalGalvo,
    /// Simulated time at the end of the run, µs.
    pub end_us: u64,
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
            transcript: &report.transcript,
            task_steps: &report.task_steps,
            galvo_physics: PhysicalGalvo::default(),
            end_us: report.end_time_us,
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

/// The accepted settings over time, replayed from the transcript with the
/// firmware's own parser: `(sent µs, replied µs, settings after)`.
struct SettingsTimeline {
    changes: Vec<(u64, u64, Settings)>,
}

impl SettingsTimeline {
    fn from_transcript(transcript: &Transcript) -> Self {
        let mut settings = Settings::default();
        let mut changes = Vec::new();
        let mut pending: Option<(u64, Command)> = None;
        for (t, line) in &transcript.lines {
            if let Some(sent) = line.strip_prefix("> ") {
                pending = match parse_line(sent) {
                    Ok(Some(c @ (Command::Set { .. } | Command::Laser(_)))) => Some((*t, c)),
                    _ => None,
                };
                continue;
            }
            let accepted = line == "ok";
            if !(accepted || line.starts_with("error:")) {
                continue;
            }
            let Some((sent, command)) = pending.take() else {
                continue;
            };
            if !accepted {
                continue;
            }
            match command {
                Command::Set { param, value } => {
                    if settings.set(param, value).is_err() {
                        continue;
                    }
                }
                Command::Laser(mode) => settings.laser_mode = mode,
                _ => continue,
            }
            changes.push((sent, *t, settings));
        }
        Self { changes }
    }

    /// Largest marking speed in force at any time up to `t_us`, mm/s.
    fn max_mark_speed_mm_s(&self, t_us: u64) -> f64 {
        self.changes
            .iter()
            .take_while(|(sent, _, _)| *sent <= t_us)
            .map(|(_, _, s)| s.galvo.mark_speed_mm_s)
            .fold(Settings::default().galvo.mark_speed_mm_s, f64::max)
    }

    /// Largest arrival deadband in force at any time up to `t_us`, deg.
    fn max_deadband_deg(&self, t_us: u64) -> f64 {
        self.changes
            .iter()
            .take_while(|(sent, _, _)| *sent <= t_us)
            .map(|(_, _, s)| s.deadband_deg)
            .fold(Settings::default().deadband_deg, f64::max)
    }

    /// Whether `laser dwell` mode is certainly in force at `t_us`: the
    /// last accepted change replied before then set it, and a change in
    /// flight at `t_us` (sent by then, replied at or after it: the
    /// transcript cannot order it against what happened in that instant)
    /// keeps it.
    fn certainly_dwell_mode(&self, t_us: u64) -> bool {
        let mut mode = Settings::default().laser_mode;
        for (sent, replied, s) in &self.changes {
            if *sent > t_us {
                break;
            }
            if *replied >= t_us && (mode != LaserMode::Dwell || s.laser_mode != LaserMode::Dwell) {
                return false;
            }
            mode = s.laser_mode;
        }
        mode == LaserMode::Dwell
    }
}

/// Something after which every laser must go dark.
#[derive(Debug, Clone)]
struct Shutdown {
    t_us: u64,
    why: String,
}

/// Windows in which every laser must be dark: from 1 ms after the first
/// shutdown since the last run start until the next start. Galvo samples
/// computed before that next start stay under the rule even when output
/// later. `(shutdown, next start µs or None)`.
fn dark_windows(inputs: &SafetyInputs<'_>) -> Vec<(Shutdown, Option<u64>)> {
    // Sequencer events in processing order, underruns (from the galvo
    // loop) placed before the events at or after their time.
    let mut underruns = inputs.underruns_ns.iter().map(|ns| ns / 1000).peekable();
    let mut windows = Vec::new();
    let mut first: Option<Shutdown> = None;
    for event in inputs.events {
        while let Some(t_us) = underruns.next_if(|t| *t <= event.t_us) {
            first.get_or_insert(Shutdown {
                t_us,
                why: "galvo underrun (detected by the loop)".into(),
            });
        }
        match &event.event {
            SequencerEvent::Stopped { why }
                if !STOPS_THAT_ARE_NOT_SHUTDOWNS.contains(&why.as_str()) =>
            {
                first.get_or_insert(Shutdown {
                    t_us: event.t_us,
                    why: why.clone(),
                });
            }
            SequencerEvent::RunStarted => {
                if let Some(shutdown) = first.take() {
                    windows.push((shutdown, Some(event.t_us)));
                }
            }
            _ => {}
        }
    }
    for t_us in underruns {
        first.get_or_insert(Shutdown {
            t_us,
            why: "galvo underrun (detected by the loop)".into(),
        });
    }
    if let Some(shutdown) = first {
        windows.push((shutdown, None));
    }
    windows
}

/// (a) Every laser dark from 1 ms after a shutdown until the next start.
fn dark_after_stops(inputs: &SafetyInputs<'_>) -> Vec<Violation> {
    let windows = dark_windows(inputs);
    let mut found = Vec::new();
    // Galvo: each window scans the stretches up to the next window's start
    // (a later window's rule includes this one's).
    let galvo = &inputs.galvo;
    for (i, (shutdown, next_start)) in windows.iter().enumerate() {
        let from_ns = (shutdown.t_us + DARK_WITHIN_US) * 1000;
        let until_ns = windows
            .get(i + 1)
            .map_or(u64::MAX, |(s, _)| (s.t_us + DARK_WITHIN_US) * 1000);
        let computed_before_ns = next_start.map_or(u64::MAX, |t| t * 1000);
        // A later window starting as early includes this one's rule.
        if from_ns >= until_ns {
            continue;
        }
        let begin = galvo.partition_point(|s| s.last_ns() < from_ns);
        let mut lit: Option<(u64, u64, u64)> = None; // first ns, last ns, samples
        for s in galvo[begin..].iter().take_while(|s| s.start_ns < until_ns) {
            if !s.laser || s.computed_ns >= computed_before_ns {
                continue;
            }
            // Samples output in [from_ns, until_ns).
            let skip = from_ns.saturating_sub(s.start_ns).div_ceil(s.period_ns);
            let end = until_ns
                .saturating_sub(s.start_ns)
                .div_ceil(s.period_ns)
                .min(s.count);
            if skip >= end {
                continue;
            }
            let first_ns = s.start_ns + skip * s.period_ns;
            let entry = lit.get_or_insert((first_ns, first_ns, 0));
            entry.1 = s.start_ns + (end - 1) * s.period_ns;
            entry.2 += end - skip;
        }
        if let Some((first_ns, last_ns, samples)) = lit {
            found.push(Violation {
                kind: ViolationKind::LitAfterStop,
                t_us: first_ns / 1000,
                detail: format!(
                    "galvo laser lit {:.3} ms after {} (processed at {:.3} ms): {samples} lit samples until {:.3} ms",
                    (first_ns as f64 / 1000.0 - shutdown.t_us as f64) / 1000.0,
                    shutdown.why,
                    shutdown.t_us as f64 / 1000.0,
                    last_ns as f64 / 1e6,
                ),
            });
        }
        // Gimbal: off from 1 ms after the shutdown until the next start.
        let from_us = shutdown.t_us + DARK_WITHIN_US;
        let until_us = next_start.unwrap_or(u64::MAX);
        if from_us >= until_us {
            continue;
        }
        let on_at_start = gimbal_laser_at(inputs.gimbal_laser, from_us);
        let switched_on = inputs
            .gimbal_laser
            .iter()
            .find(|(t, on)| *on && *t > from_us && *t < until_us)
            .map(|(t, _)| *t);
        if let Some(t_us) = on_at_start.then_some(from_us).or(switched_on) {
            found.push(Violation {
                kind: ViolationKind::LitAfterStop,
                t_us,
                detail: format!(
                    "gimbal laser lit {:.3} ms after {} (processed at {:.3} ms)",
                    (t_us - shutdown.t_us) as f64 / 1000.0,
                    shutdown.why,
                    shutdown.t_us as f64 / 1000.0
                ),
            });
        }
    }
    found
}

fn gimbal_laser_at(switches: &[(u64, bool)], t_us: u64) -> bool {
    let n = switches.partition_point(|(t, _)| *t <= t_us);
    n > 0 && switches[n - 1].1
}

/// (b) The galvo laser is dark whenever the DAC codes step by more than
/// marking allows (marking speed in force × sample period × 1.5 + 0.2 mm
/// for code quantisation): a sample that steps that far must be dark (the
/// mirrors move to it during its sample period, with its laser state).
fn galvo_jumps_dark(inputs: &SafetyInputs<'_>, timeline: &SettingsTimeline) -> Vec<Violation> {
    let mut found = Vec::new();
    // (first µs, last µs, steps, largest mm) of the current lit jump.
    let mut episode: Option<(u64, u64, u32, f64)> = None;
    let mut flush = |episode: &mut Option<(u64, u64, u32, f64)>| {
        if let Some((first, last, steps, largest)) = episode.take() {
            found.push(Violation {
                kind: ViolationKind::LitGalvoJump,
                t_us: first,
                detail: format!(
                    "galvo laser lit while the mirrors jumped: {steps} steps until {:.3} ms, largest {largest:.2} mm per sample",
                    last as f64 / 1000.0
                ),
            });
        }
    };
    for w in inputs.galvo.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        // The mirrors move from `a`'s codes to `b`'s during `b`'s sample,
        // with `b`'s laser state (the DAC and the laser switch together).
        if (a.x_code, a.y_code) == (b.x_code, b.y_code) || !b.laser {
            continue;
        }
        let (Some(p), Some(q)) = (
            inputs.galvo_physics.spot_cm(a.x_code, a.y_code),
            inputs.galvo_physics.spot_cm(b.x_code, b.y_code),
        ) else {
            continue;
        };
        let step_mm = 10.0 * (p.0 - q.0).hypot(p.1 - q.1);
        let t_us = b.start_ns / 1000;
        let period_s = b.period_ns as f64 * 1e-9;
        let allowed_mm = timeline.max_mark_speed_mm_s(t_us) * period_s * 1.5 + 0.2;
        if step_mm <= allowed_mm {
            continue;
        }
        match episode.as_mut() {
            Some(e) if t_us <= e.1 + DARK_WITHIN_US => {
                e.1 = t_us;
                e.2 += 1;
                e.3 = e.3.max(step_mm);
            }
            _ => {
                flush(&mut episode);
                episode = Some((t_us, t_us, 1, step_mm));
            }
        }
    }
    flush(&mut episode);
    found
}

/// Lit intervals of the gimbal laser within `[from, until)`, µs.
fn gimbal_lit_intervals(switches: &[(u64, bool)], from: u64, until: u64) -> Vec<(u64, u64)> {
    let mut out = Vec::new();
    let mut lit_since = gimbal_laser_at(switches, from).then_some(from);
    let begin = switches.partition_point(|(t, _)| *t <= from);
    for &(t, on) in switches[begin..].iter().take_while(|(t, _)| *t < until) {
        match (on, lit_since) {
            (true, None) => lit_since = Some(t),
            (false, Some(start)) => {
                if t > start {
                    out.push((start, t));
                }
                lit_since = None;
            }
            _ => {}
        }
    }
    if let Some(start) = lit_since
        && until > start
    {
        out.push((start, until));
    }
    out
}

/// (b) The gimbal laser is dark from a run's start until the servo task
/// confirmed the arrival at its first point (travel to a figure is dark
/// in every laser mode).
fn gimbal_travel_dark(inputs: &SafetyInputs<'_>) -> Vec<Violation> {
    let mut found = Vec::new();
    let events = inputs.events;
    for (i, e) in events.iter().enumerate() {
        if e.event != SequencerEvent::RunStarted {
            continue;
        }
        let mut moved = false;
        let mut end = None;
        for later in &events[i + 1..] {
            match later.event {
                SequencerEvent::GimbalMoveSent => moved = true,
                SequencerEvent::GimbalArrived
                | SequencerEvent::RunStarted
                | SequencerEvent::Stopped { .. } => {
                    end = Some(later.t_us);
                    break;
                }
            }
        }
        if !moved {
            continue;
        }
        let until = end.unwrap_or(inputs.end_us);
        if let Some(&(from, to)) = gimbal_lit_intervals(inputs.gimbal_laser, e.t_us, until).first()
        {
            found.push(Violation {
                kind: ViolationKind::LitTravel,
                t_us: from,
                detail: format!(
                    "gimbal laser lit while travelling to the first point of the run started at {:.3} ms, for {:.3} ms before an arrival was confirmed",
                    e.t_us as f64 / 1000.0,
                    (to - from) as f64 / 1000.0
                ),
            });
        }
    }
    found
}

/// (b) In `laser dwell` mode the gimbal laser is lit only after a
/// confirmed arrival at the current point and while both servos truly are
/// within the deadband (+0.15° for quantisation) of their targets.
fn gimbal_dwell_mode(inputs: &SafetyInputs<'_>, timeline: &SettingsTimeline) -> Vec<Violation> {
    let mut found = Vec::new();
    // Laser switched on without a confirmed arrival: the arrival state
    // after the events processed before the switch.
    let events = inputs.events;
    for (j, &(t, on)) in inputs.gimbal_laser.iter().enumerate() {
        if !on || !timeline.certainly_dwell_mode(t) {
            continue;
        }
        let before = events.partition_point(|e| e.laser_switches_before <= j);
        // Every event but an arrival means the gimbal left its point.
        let arrived = events[..before]
            .last()
            .is_some_and(|e| e.event == SequencerEvent::GimbalArrived);
        if !arrived {
            found.push(Violation {
                kind: ViolationKind::LitWithoutArrival,
                t_us: t,
                detail: "gimbal laser switched on in dwell mode without a confirmed arrival".into(),
            });
        }
    }
    // Lit while a servo was truly away from its target.
    let mut last_flagged: Option<u64> = None;
    for s in inputs.servos {
        if !s.laser || !timeline.certainly_dwell_mode(s.t_us) {
            continue;
        }
        let tolerance = timeline.max_deadband_deg(s.t_us) + 0.15;
        let off = [("yaw", s.yaw), ("pitch", s.pitch)]
            .into_iter()
            .filter_map(|(name, st)| st.map(|st| (name, st)))
            .map(|(name, st)| (name, (st.angle_deg - st.target_deg).abs()))
            .find(|(_, error)| *error > tolerance);
        if let Some((name, error)) = off {
            if last_flagged.is_some_and(|t| s.t_us <= t + 10_000) {
                last_flagged = Some(s.t_us);
                continue;
            }
            last_flagged = Some(s.t_us);
            found.push(Violation {
                kind: ViolationKind::LitWithoutArrival,
                t_us: s.t_us,
                detail: format!(
                    "gimbal laser lit in dwell mode while the {name} servo was {error:.2} deg from its target (deadband {:.2} deg)",
                    tolerance - 0.15
                ),
            });
        }
    }
    found
}

/// (c) Exactly one closing reply per line, in order; notices are whole
/// `[…]` lines.
fn one_reply_per_line(transcript: &Transcript) -> Vec<Violation> {
    let mut found = Vec::new();
    let mut add = |t_us: u64, detail: String| {
        found.push(Violation {
            kind: ViolationKind::Replies,
            t_us,
            detail,
        })
    };
    // Lines awaiting their closing reply, oldest first (a host may type
    // ahead), and the line closed last.
    let mut pending: VecDeque<(u64, &str)> = VecDeque::new();
    let mut last_closed: Option<&str> = None;
    for (t, line) in &transcript.lines {
        let t = *t;
        if let Some(sent) = line.strip_prefix("> ") {
            pending.push_back((t, sent));
            continue;
        }
        if line.starts_with('[') {
            if !line.ends_with(']') {
                add(t, format!("notice cut or glued to a reply: {line:?}"));
            }
            continue;
        }
        let closing = line == "ok" || line.starts_with("error:");
        if closing && let Some((_, sent)) = pending.pop_front() {
            last_closed = Some(sent);
            continue;
        }
        if !pending.is_empty() {
            // A data line of the oldest line awaiting its reply.
            continue;
        }
        let detail = match (closing, last_closed) {
            (true, Some(sent)) => format!("{sent:?} got a second closing reply {line:?}"),
            (false, Some(sent)) => format!("line {line:?} after the closing reply of {sent:?}"),
            (_, None) => format!("{line:?} before any command line"),
        };
        add(t, detail);
    }
    for (t, sent) in pending {
        add(t, format!("{sent:?} got no closing reply"));
    }
    found
}

/// (d) No firmware task step longer than [`MAX_STEP_NS`] of CPU time.
fn short_steps(steps: &[TaskSteps]) -> Vec<Violation> {
    let mut found = Vec::new();
    for task in steps.iter().filter(|s| s.kind == TaskKind::Firmware) {
        for &(t_us, cpu_ns) in task.long_steps.iter().filter(|(_, ns)| *ns > MAX_STEP_NS) {
            found.push(Violation {
                kind: ViolationKind::LongStep,
                t_us,
                detail: format!(
                    "{} task step took {:.3} ms of CPU time (limit {:.3} ms)",
                    task.name,
                    cpu_ns as f64 / 1e6,
                    MAX_STEP_NS as f64 / 1e6
                ),
            });
        }
        let unlisted = task
            .long_step_count
            .saturating_sub(task.long_steps.len() as u64);
        if unlisted > 0 {
            found.push(Violation {
                kind: ViolationKind::LongStep,
                t_us: task.long_steps.last().map_or(0, |s| s.0),
                detail: format!("{} task: {unlisted} more long steps", task.name),
            });
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    fn transcript(lines: &[(u64, &str)]) -> Transcript {
        Transcript {
            lines: lines.iter().map(|(t, l)| (*t, (*l).to_owned())).collect(),
            ..Transcript::default()
        }
    }

    fn inputs<'a>(
        transcript: &'a Transcript,
        events: &'a [EventRecord],
        gimbal_laser: &'a [(u64, bool)],
        galvo: Vec<GalvoStretch>,
    ) -> SafetyInputs<'a> {
        SafetyInputs {
            gimbal_laser,
            galvo,
            underruns_ns: &[],
            events,
            servos: &[],
            transcript,
            task_steps: &[],
            galvo_physics: PhysicalGalvo::default(),
            end_us: 1_000_000,
        }
    }

    fn event(t_us: u64, event: SequencerEvent) -> EventRecord {
        EventRecord {
            t_us,
            event,
            laser_switches_before: 0,
        }
    }

    fn stopped(t_us: u64, why: &str) -> EventRecord {
        event(t_us, SequencerEvent::Stopped { why: why.into() })
    }

    /// 100 samples at 10 µs from `start_us`, computed at `computed_us`.
    fn stretch(start_us: u64, code: u16, laser: bool, computed_us: u64) -> GalvoStretch {
        GalvoStretch {
            start_ns: start_us * 1000,
            period_ns: 10_000,
            count: 100,
            x_code: code,
            y_code: 2048,
            laser,
            computed_ns: computed_us * 1000,
        }
    }

    fn kinds(v: &[Violation]) -> Vec<ViolationKind> {
        v.iter().map(|v| v.kind).collect()
    }

    #[test]
    fn one_closing_reply_per_line_and_whole_notices() {
        let good = transcript(&[
            (0, "> status"),
            (0, "uptime: 1.000 s"),
            (
                5,
                "[error: servo 1 fault (NoResponse); pattern stopped, laser off]",
            ),
            (0, "ok"),
            (9, "[info: servo 1 answering again]"),
            (10, "> set dwell_ms -4"),
            (10, "error: dwell_ms out of range [0, 60000]"),
        ]);
        assert_eq!(one_reply_per_line(&good), []);
        // A host typing ahead gets the replies in order.
        let ahead = transcript(&[
            (0, "> get dwell_ms"),
            (0, "> status"),
            (1, "dwell_ms = 1000"),
            (1, "ok"),
            (1, "uptime: 1.000 s"),
            (1, "ok"),
        ]);
        assert_eq!(one_reply_per_line(&ahead), []);
        let cases: &[(&[(u64, &str)], &str)] = &[
            (
                &[(0, "> params"), (1, "oq_cm = 25")],
                "got no closing reply",
            ),
            (
                &[(0, "> stop"), (0, "ok"), (0, "ok")],
                "second closing reply",
            ),
            (
                &[(0, "> stop"), (0, "ok"), (0, "oq_cm = 25")],
                "after the closing reply",
            ),
            (&[(0, "ok")], "before any command line"),
            // A reply glued onto a cut line: its closer is not a line.
            (
                &[
                    (0, "> params"),
                    (1, "oq_cm = 2ok"),
                    (2, "> stop"),
                    (2, "ok"),
                ],
                "got no closing reply",
            ),
            (
                &[(0, "> params"), (1, "[error: servo 1 fauok"), (2, "ok")],
                "cut or glued",
            ),
        ];
        for (lines, want) in cases {
            let found = one_reply_per_line(&transcript(lines));
            assert!(
                found.iter().any(|v| v.detail.contains(want)),
                "{lines:?}: {found:?}"
            );
            assert!(found.iter().all(|v| v.kind == ViolationKind::Replies));
        }
    }

    #[test]
    fn galvo_samples_computed_before_the_next_start_are_dark_from_1_ms_after_a_stop() {
        let t = transcript(&[]);
        let events = [
            stopped(1_000, "stop command"),
            event(5_000, SequencerEvent::RunStarted),
        ];
        // Lit from 1.5 to 2.49 ms (computed before the stop): the samples
        // from 2 ms on are too late.
        let late = vec![
            stretch(1_500, 100, true, 900),
            stretch(2_500, 100, false, 1_900),
        ];
        let found = dark_after_stops(&inputs(&t, &events, &[], late));
        assert_eq!(kinds(&found), [ViolationKind::LitAfterStop]);
        assert_eq!(found[0].t_us, 2_000);
        assert!(found[0].detail.contains("50 lit samples"), "{found:?}");
        // Dark in time (the last lit sample at 1.99 ms), then lit by the new
        // run (computed after its start).
        let fine = vec![
            stretch(1_000, 100, true, 900),
            stretch(6_000, 100, true, 5_000),
        ];
        assert_eq!(dark_after_stops(&inputs(&t, &events, &[], fine)), []);
        // Old content output after the new start is still the old run's.
        let stale = vec![stretch(6_000, 100, true, 4_000)];
        assert_eq!(
            kinds(&dark_after_stops(&inputs(&t, &events, &[], stale))),
            [ViolationKind::LitAfterStop]
        );
        // A completed pattern's last samples may still be lit.
        let complete = [stopped(1_000, "pattern complete")];
        let tail = vec![
            stretch(1_000, 100, true, 900),
            stretch(2_000, 100, true, 1_000),
        ];
        assert_eq!(dark_after_stops(&inputs(&t, &complete, &[], tail)), []);
    }

    #[test]
    fn the_gimbal_laser_is_off_from_1_ms_after_a_stop_until_the_next_start() {
        let t = transcript(&[]);
        let events = [
            stopped(1_000, "servo fault"),
            event(9_000, SequencerEvent::RunStarted),
        ];
        let switched_late = [(0, true), (2_500, false)];
        let found = dark_after_stops(&inputs(&t, &events, &switched_late, vec![]));
        assert_eq!(kinds(&found), [ViolationKind::LitAfterStop]);
        assert!(
            found[0]
                .detail
                .contains("gimbal laser lit 1.000 ms after servo fault")
        );
        let switched_on_again = [(0, true), (1_000, false), (4_000, true)];
        let found = dark_after_stops(&inputs(&t, &events, &switched_on_again, vec![]));
        assert_eq!(found[0].t_us, 4_000);
        let fine = [(0, true), (1_000, false), (9_000, true)];
        assert_eq!(dark_after_stops(&inputs(&t, &events, &fine, vec![])), []);
    }

    #[test]
    fn a_lit_step_larger_than_marking_allows_is_a_lit_jump() {
        let t = transcript(&[]);
        let timeline = SettingsTimeline::from_transcript(&t);
        // One DAC code is ~0.09 mm; marking at 1 m/s allows 0.215 mm per
        // 10 µs sample.
        let marking = vec![
            stretch(0, 2000, true, 0).with_count(1),
            stretch(10, 2002, true, 0).with_count(1),
        ];
        assert_eq!(
            galvo_jumps_dark(&inputs(&t, &[], &[], marking), &timeline),
            []
        );
        let jump = vec![
            stretch(0, 2000, true, 0).with_count(1),
            stretch(10, 2100, true, 0).with_count(1),
            stretch(20, 2200, false, 0).with_count(1),
            stretch(30, 2300, false, 0).with_count(1),
        ];
        let found = galvo_jumps_dark(&inputs(&t, &[], &[], jump.clone()), &timeline);
        assert_eq!(kinds(&found), [ViolationKind::LitGalvoJump]);
        assert!(found[0].detail.contains("1 steps"), "{found:?}");
        assert_eq!(found[0].t_us, 10);
        // Leaving a lit point dark: the laser is off while the mirrors move.
        let leaving = vec![
            stretch(0, 2000, true, 0).with_count(1),
            stretch(10, 2100, false, 0).with_count(1),
        ];
        assert_eq!(
            galvo_jumps_dark(&inputs(&t, &[], &[], leaving), &timeline),
            []
        );
        // At the fastest marking `set` accepts (20 m/s: 0.5 mm per
        // sample), 100 codes (~9 mm) per sample are still a jump.
        let fast = transcript(&[(0, "> set galvo.mark_speed_mm_s 20000"), (0, "ok")]);
        let timeline = SettingsTimeline::from_transcript(&fast);
        assert_eq!(
            kinds(&galvo_jumps_dark(&inputs(&fast, &[], &[], jump), &timeline)),
            [ViolationKind::LitGalvoJump]
        );
    }

    #[test]
    fn the_gimbal_is_dark_until_the_first_arrival_of_a_run() {
        let t = transcript(&[]);
        let events = [
            event(0, SequencerEvent::RunStarted),
            event(0, SequencerEvent::GimbalMoveSent),
            event(130_000, SequencerEvent::GimbalArrived),
            event(300_000, SequencerEvent::GimbalMoveSent),
        ];
        // Lit from the start (auto today): lit travel.
        let lit_travel = [(0, true)];
        let found = gimbal_travel_dark(&inputs(&t, &events, &lit_travel, vec![]));
        assert_eq!(kinds(&found), [ViolationKind::LitTravel]);
        assert!(found[0].detail.contains("for 130.000 ms"), "{found:?}");
        // Lit from the arrival on, also while moving to the next point.
        let lit_on_figure = [(0, false), (130_000, true)];
        assert_eq!(
            gimbal_travel_dark(&inputs(&t, &events, &lit_on_figure, vec![])),
            []
        );
    }

    #[test]
    fn dwell_mode_lights_only_confirmed_arrivals_where_the_servos_truly_are() {
        let t = transcript(&[(0, "> laser dwell"), (0, "ok")]);
        let timeline = SettingsTimeline::from_transcript(&t);
        let events = [
            event(1_000, SequencerEvent::RunStarted),
            event(1_000, SequencerEvent::GimbalMoveSent),
            event(50_000, SequencerEvent::GimbalArrived),
        ];
        let at = |angle_deg: f64| {
            Some(crate::recorder::ServoState {
                angle_deg,
                target_deg: 10.0,
            })
        };
        let sample = |t_us, yaw_deg| ServoSample {
            t_us,
            yaw: at(yaw_deg),
            pitch: at(10.0),
            laser: true,
        };
        let on_arrival = [(50_000, true)];
        let servos = [sample(50_000, 9.6), sample(52_000, 10.0)];
        let mut good = inputs(&t, &events, &on_arrival, vec![]);
        good.servos = &servos;
        assert_eq!(gimbal_dwell_mode(&good, &timeline), []);
        // Switched on before the arrival was confirmed (the arrival event
        // comes after the switch).
        let early = [(20_000, true)];
        let mut later_arrival = events.clone();
        later_arrival[2].laser_switches_before = 1;
        let found = gimbal_dwell_mode(&inputs(&t, &later_arrival, &early, vec![]), &timeline);
        assert_eq!(kinds(&found), [ViolationKind::LitWithoutArrival]);
        // A confirmed arrival (a corrupted reading) far from the target.
        let far = [sample(50_000, 7.0)];
        let mut fooled = inputs(&t, &events, &on_arrival, vec![]);
        fooled.servos = &far;
        let found = gimbal_dwell_mode(&fooled, &timeline);
        assert!(
            found[0].detail.contains("yaw servo was 3.00 deg"),
            "{found:?}"
        );
        // Not in dwell mode: not this rule's business.
        let auto = transcript(&[]);
        let auto_timeline = SettingsTimeline::from_transcript(&auto);
        let mut in_auto = inputs(&auto, &later_arrival, &early, vec![]);
        in_auto.servos = &far;
        assert_eq!(gimbal_dwell_mode(&in_auto, &auto_timeline), []);
    }

    #[test]
    fn firmware_steps_over_1_ms_are_violations_simulator_ones_are_not() {
        let step = |name, kind, long: Vec<(u64, u64)>| TaskSteps {
            name,
            kind,
            polls: 10,
            total_cpu_ns: 0,
            max_cpu_ns: long.iter().map(|s| s.1).max().unwrap_or(0),
            max_at_us: 0,
            long_step_count: long.len() as u64,
            long_steps: long,
        };
        let steps = [
            step("sequencer", TaskKind::Firmware, vec![(7, 21_000_000)]),
            step("host (script)", TaskKind::Simulator, vec![(8, 5_000_000)]),
            step("galvo", TaskKind::Firmware, vec![]),
        ];
        let found = short_steps(&steps);
        assert_eq!(kinds(&found), [ViolationKind::LongStep]);
        assert_eq!(found[0].t_us, 7);
        assert!(
            found[0]
                .detail
                .contains("sequencer task step took 21.000 ms")
        );
    }

    impl GalvoStretch {
        fn with_count(mut self, count: u64) -> Self {
            self.count = count;
            self
        }
    }
}
