//! The laser controls of a Class 3B/4 product (issue 25,
//! `docs/laser-safety.md`) in the simulator: the remote interlock and key
//! switch (`@interlock`, `@key` script steps), the emission indicator and
//! `arm`, on the galvo (whose lit DAC samples are recorded one by one)
//! and the gimbal, all under the safety checker (rule (g) included).

use laser_sim::safety::{GalvoStretch, ViolationKind, check, galvo_stretches};
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{UNTIL_STEP_FIXES, assert_safe_allowing, run_with};

/// The default emission indicator delay, µs.
const DELAY_US: u64 = 3_000_000;

fn run(script: &str) -> SimReport {
    let report = run_with(script, SimOptions::default());
    assert!(report.laser_controls.is_some(), "the controls are fitted");
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    report
}

/// Lit galvo stretches.
fn lit(report: &SimReport) -> Vec<GalvoStretch> {
    galvo_stretches(&report.dac)
        .into_iter()
        .filter(|s| s.laser)
        .collect()
}

/// When the host sent `line` (the `n`th time), µs.
fn sent_at(report: &SimReport, line: &str, n: usize) -> u64 {
    report
        .transcript
        .lines
        .iter()
        .filter(|(_, l)| l.strip_prefix("> ") == Some(line))
        .nth(n)
        .unwrap_or_else(|| panic!("{line:?} #{n} not sent"))
        .0
}

/// The data lines of the `n`th `status` reply.
fn status_line(report: &SimReport, n: usize) -> String {
    let lines = &report.transcript.lines;
    let start = lines
        .iter()
        .enumerate()
        .filter(|(_, (_, l))| l == "> status")
        .nth(n)
        .expect("status sent")
        .0;
    lines[start..]
        .iter()
        .find(|(_, l)| l.starts_with("laser controls:"))
        .expect("a laser controls line")
        .1
        .clone()
}

#[test]
fn power_up_is_not_armed_and_nothing_lights_until_arm() {
    let report = run(
        "@interlock closed\ntarget galvo\npattern tuning 0 0 8 once\n\
         wait 1500\nstatus\n",
    );
    assert!(lit(&report).is_empty(), "lit before arm");
    assert_eq!(
        status_line(&report, 0),
        "laser controls: interlock closed, key on, not armed since power-up"
    );
    let record = report.laser_controls.as_ref().unwrap();
    assert_eq!(
        record.indicator,
        [(0, false)],
        "the indicator never came on"
    );
}

#[test]
fn arm_lights_the_indicator_first_and_the_laser_only_after_the_delay() {
    let report =
        run("target galvo\n@key on\nwait 50\narm\npattern tuning 0 0 8\nwait 5000\nstop\n");
    let armed = sent_at(&report, "arm", 0);
    let record = report.laser_controls.as_ref().unwrap();
    let (on_at, _) = *record.indicator.iter().find(|(_, on)| *on).expect("on");
    assert!(
        on_at >= armed && on_at - armed < 10_000,
        "{on_at} vs {armed}"
    );
    let lit = lit(&report);
    let first = lit.first().expect("lit after the delay").start_ns / 1000;
    assert!(
        first >= on_at + DELAY_US,
        "lit at {first} µs, indicator {on_at}"
    );
    // The pattern started before the delay ended and lights within a few
    // ms of its end (the loop keeps drawing, dark, until then).
    assert!(first < on_at + DELAY_US + 50_000, "lit at {first} µs");
}

#[test]
fn an_interlock_opened_mid_pattern_darkens_within_1_ms_and_latches_until_reset() {
    let report = run(
        "target galvo\n@interlock closed\nwait 50\narm\nwait 3100\npattern tuning 0 0 8\n\
         wait 500\n@interlock open\nwait 300\n@interlock closed\nwait 500\nstatus\n\
         pattern tuning 0 0 8\nwait 1000\nstop\narm\npattern tuning 0 0 8\nwait 4000\nstop\n",
    );
    let record = report.laser_controls.as_ref().unwrap();
    let opened = record
        .interlock_closed
        .iter()
        .find(|(_, closed)| !closed)
        .unwrap()
        .0;
    let rearmed = sent_at(&report, "arm", 1);
    let lit = lit(&report);
    assert!(
        lit.iter().any(|s| s.start_ns / 1000 < opened),
        "lit before the opening"
    );
    let last_before = lit
        .iter()
        .filter(|s| s.start_ns / 1000 < rearmed)
        .map(|s| s.last_ns() / 1000)
        .max()
        .unwrap();
    assert!(
        last_before <= opened + 1_000,
        "lit until {last_before} µs, opened at {opened} µs"
    );
    assert!(
        status_line(&report, 0).ends_with("latched: the interlock opened"),
        "{}",
        status_line(&report, 0)
    );
    let first_after = lit
        .iter()
        .map(|s| s.start_ns / 1000)
        .find(|t| *t > opened)
        .expect("lit again after the reset");
    assert!(
        first_after >= rearmed + DELAY_US,
        "{first_after} vs {rearmed}"
    );
    assert!(
        report
            .transcript
            .notices
            .iter()
            .any(|(_, n)| n.contains("latched: the interlock opened")),
        "{:?}",
        report.transcript.notices
    );
}

#[test]
fn arm_is_refused_while_the_interlock_is_open_or_the_key_off() {
    let report = run(
        "@interlock open\narm\n@interlock closed\n@key off\nwait 100\narm\n\
         @key on\nwait 100\narm\n",
    );
    let replies: Vec<&str> = report
        .transcript
        .lines
        .iter()
        .map(|(_, l)| l.as_str())
        .filter(|l| *l == "ok" || l.starts_with("error"))
        .collect();
    assert_eq!(
        replies,
        [
            "error: interlock open: close it, then arm",
            "error: key switch off: turn it on, then arm",
            "ok"
        ]
    );
}

#[test]
fn the_key_switch_latches_like_the_interlock_on_the_gimbal() {
    // Gimbal goto: lit while holding (laser auto).
    let report = run(
        "@key on\nwait 50\narm\nwait 3100\ngoto 0 0\nwait 1000\n@key off\nwait 200\n\
         @key on\nwait 200\n@realtime ?\nstatus\n",
    );
    let record = report.laser_controls.as_ref().unwrap();
    let off = record.key_on.iter().find(|(_, on)| !on).unwrap().0;
    let gimbal = &report.recording.laser_events;
    assert!(
        gimbal.iter().any(|(t, on)| *on && *t < off),
        "lit before: {gimbal:?}"
    );
    let (last_t, last_on) = *gimbal.last().unwrap();
    assert!(!last_on && last_t <= off + 1_000, "{gimbal:?} off at {off}");
    assert!(status_line(&report, 0).ends_with("latched: the key switch was off"));
    assert!(
        report
            .transcript
            .lines
            .iter()
            .any(|(_, l)| l.starts_with("<Door:0|")),
        "grbl's Door:0 (closed, waiting for the reset)"
    );
}

#[test]
fn the_checker_flags_a_laser_lit_without_the_controls() {
    // The same lit run, checked against controls that were never armed:
    // rule (g) must see it.
    let mut report = run_with(
        "target galvo\nwait 50\narm\nwait 3100\npattern tuning 0 0 8\nwait 500\nstop\n",
        SimOptions {
            laser_controls: true,
            ..SimOptions::default()
        },
    );
    assert!(!lit(&report).is_empty());
    report.laser_controls.as_mut().unwrap().indicator = vec![(0, false)];
    assert!(
        check(&report)
            .iter()
            .any(|v| v.kind == ViolationKind::LitWithoutControls)
    );
}
