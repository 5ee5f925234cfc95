//! The safety checker (`laser_sim::safety`) against the known defects of
//! issue 9: each reproducer from the issue runs in the simulator and the
//! checker must report the violation the defect causes.
//!
//! Long task steps are tolerated (`UNTIL_STEP_FIXES`) except where they
//! are the point: one noisy poll on a loaded machine must not fail a
//! laser-safety test.
//!
//! The defects are fixed on other branches. Each `detects_…` test has an
//! ignored `holds_after_…` twin running the same scenario and demanding
//! no violation at all. **After merging a fix**, delete (or ignore) the
//! `detects_…` tests its ignore reason names and un-ignore their
//! `holds_after_…` twins.

use laser_sim::safety::{Violation, ViolationKind, check, report_text};
use laser_sim::servo_port::{BusFaults, SilentWindow};
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{
    UNTIL_STEP_FIXES, assert_safe, assert_safe_allowing, run_with, sent_at, violations_of,
};

/// Violations of `kind` whose detail contains every one of `words`.
fn matching(report: &SimReport, kind: ViolationKind, words: &[&str]) -> Vec<Violation> {
    violations_of(report, kind)
        .into_iter()
        .filter(|v| words.iter().all(|w| v.detail.contains(w)))
        .collect()
}

fn assert_reported(report: &SimReport, kind: ViolationKind, words: &[&str]) -> Vec<Violation> {
    let found = matching(report, kind, words);
    assert!(
        !found.is_empty(),
        "expected a {} violation mentioning {words:?}; the checker found:\n{}",
        kind.name(),
        report_text(&check(report))
    );
    found
}

// Item 1: a sequencer that gave up on the galvo ("galvo not responding;
// stopped") never told the loop, and `stop` then sends nothing: the
// galvo stays lit for seconds.

fn galvo_not_responding() -> SimReport {
    run_with(
        "target galvo\nset dwell_ms 1000\npattern corner\nwait 100\n\
         model seed\nmodel exact\nmodel seed\nmodel exact\nmodel seed\nmodel exact\n\
         wait 100\nstop\nwait 2000\n",
        SimOptions::default(),
    )
}

#[test]
fn detects_the_galvo_lit_for_seconds_after_stop_when_the_sequencer_dropped_its_run() {
    let report = galvo_not_responding();
    assert!(
        report
            .transcript
            .notices
            .iter()
            .any(|(_, n)| n.contains("galvo not responding")),
        "the reproducer reaches the defect: {:?}",
        report.transcript.notices
    );
    let found = assert_reported(
        &report,
        ViolationKind::LitAfterStop,
        &["galvo laser", "stop command"],
    );
    // Lit from 1 ms after the stop (t = 200 ms) to the end of the run.
    assert_eq!(found[0].t_us, sent_at(&report, "stop") + 1_000);
}

#[test]
#[ignore = "enable after merging galvo-gate (issue 9 item 1)"]
fn holds_after_the_stop_always_reaches_the_galvo() {
    assert_safe_allowing(&galvo_not_responding(), UNTIL_STEP_FIXES);
}

// Item 2: after stop the DAC outputs up to two half buffers computed
// before it, lit (2.6–3.75 ms at 10 µs per sample, 135–313 ms at 1 ms).

fn galvo_stopped_mid_dwell(period_us: u32, stop: &str) -> SimReport {
    let (dwell_ms, wait_ms) = if period_us > 100 {
        (300, 900)
    } else {
        (20, 30)
    };
    run_with(
        &format!(
            "target galvo\nset galvo.ts_us {period_us}\nset dwell_ms {dwell_ms}\npattern corner\nwait {wait_ms}\n{stop}\nwait 500\n"
        ),
        SimOptions::default(),
    )
}

#[test]
fn detects_buffered_half_buffers_lit_after_stop() {
    for (period_us, stop, why) in [
        (10, "stop", "stop command"),
        (1000, "stop", "stop command"),
        (10, "@button", "stop button"),
        (10, "target gimbal", "actuator changed"),
    ] {
        let report = galvo_stopped_mid_dwell(period_us, stop);
        let found = assert_reported(&report, ViolationKind::LitAfterStop, &["galvo laser", why]);
        assert_eq!(found.len(), 1, "{period_us} µs, {stop}: {found:?}");
    }
}

#[test]
#[ignore = "enable after merging galvo-gate (issue 9 item 2)"]
fn holds_after_the_master_laser_gate() {
    for (period_us, stop) in [
        (10, "stop"),
        (1000, "stop"),
        (10, "@button"),
        (10, "target gimbal"),
    ] {
        assert_safe_allowing(&galvo_stopped_mid_dwell(period_us, stop), UNTIL_STEP_FIXES);
    }
}

/// A galvo dwelling on a corner (with the gimbal) when servo 1 falls silent.
fn servo_fault_while_the_galvo_dwells() -> SimReport {
    run_with(
        "target both\nset dwell_ms 1000\npattern corner\nwait 1500\n",
        SimOptions {
            faults: BusFaults {
                silent: vec![SilentWindow {
                    id: 1,
                    from_ms: 500,
                    until_ms: None,
                }],
                ..BusFaults::default()
            },
            ..SimOptions::default()
        },
    )
}

#[test]
fn detects_the_galvo_lit_after_a_servo_fault() {
    let report = servo_fault_while_the_galvo_dwells();
    assert_reported(
        &report,
        ViolationKind::LitAfterStop,
        &["galvo laser", "servo fault"],
    );
}

#[test]
#[ignore = "enable after merging galvo-gate (issue 9 item 2) and the travel fix (item 11)"]
fn holds_after_the_master_laser_gate_on_a_servo_fault() {
    assert_safe_allowing(&servo_fault_while_the_galvo_dwells(), UNTIL_STEP_FIXES);
}

// Item 3: an underrun replays stale halves lit; the laser stays lit
// ~2.5 ms after the loop learned of it.

fn slow_galvo_loop(cost_ns_per_sample: u64) -> SimReport {
    run_with(
        "target galvo\nset dwell_ms 5\npattern corner\nwait 300\n",
        SimOptions {
            galvo_cost_ns_per_sample: cost_ns_per_sample,
            ..SimOptions::default()
        },
    )
}

#[test]
fn detects_lit_underrun_replays() {
    for cost_ns_per_sample in [12_000, 20_000] {
        let report = slow_galvo_loop(cost_ns_per_sample);
        assert!(report.galvo_underruns > 0);
        assert_reported(
            &report,
            ViolationKind::LitAfterStop,
            &["galvo laser", "galvo underrun"],
        );
    }
}

#[test]
#[ignore = "enable after merging galvo-gate (issue 9 item 3)"]
fn holds_after_dark_underrun_replays() {
    assert_safe_allowing(&slow_galvo_loop(12_000), UNTIL_STEP_FIXES);
    assert_safe_allowing(&slow_galvo_loop(20_000), UNTIL_STEP_FIXES);
}

// Item 5: checking a path walks it point by point from its start for
// every point (O(n²)), in one sequencer step.

fn fine_line() -> SimReport {
    run_with(
        "set path.step_cm 0.02\npattern line -20 0 20 0 once\nwait 100\nstop\n",
        SimOptions::default(),
    )
}

#[test]
fn detects_a_path_check_holding_the_executor() {
    let found = assert_reported(
        &fine_line(),
        ViolationKind::LongStep,
        &["sequencer task step"],
    );
    assert_eq!(found[0].t_us, 0, "while `pattern line` is checked");
}

#[test]
#[ignore = "enable after merging the path fix (issue 9 item 5) and the travel fix (item 11)"]
fn holds_after_incremental_path_checks() {
    assert_safe(&fine_line());
}

// Item 6: after a silent-servo fault the next goto answers `ok` and lights
// the laser on its way to a point it will never reach.

fn goto_after_a_silent_servo() -> SimReport {
    run_with(
        "laser dwell\nset dwell_ms 100\npattern corner\nwait 2000\nlaser auto\ngoto 3 3\nwait 500\n",
        SimOptions {
            faults: BusFaults {
                silent: vec![SilentWindow {
                    id: 1,
                    from_ms: 1000,
                    until_ms: None,
                }],
                ..BusFaults::default()
            },
            ..SimOptions::default()
        },
    )
}

#[test]
fn detects_a_lit_run_on_a_dead_servo() {
    let report = goto_after_a_silent_servo();
    let goto_at = sent_at(&report, "goto 3 3");
    let found = assert_reported(&report, ViolationKind::LitTravel, &["before an arrival"]);
    assert!(
        found.iter().all(|v| v.t_us >= goto_at),
        "only the goto on the dead servo: {found:?}"
    );
}

#[test]
#[ignore = "enable after merging the dead-servo fix (issue 9 item 6)"]
fn holds_after_refusing_runs_on_a_dead_servo() {
    assert_safe_allowing(&goto_after_a_silent_servo(), UNTIL_STEP_FIXES);
}

// Item 11: in `laser auto` the gimbal lights its travel from home to a
// path's start.

fn line_from_home() -> SimReport {
    run_with(
        "pattern line -9.3 -5.1 8.7 6.2 once\nwait 3000\n",
        SimOptions::default(),
    )
}

#[test]
fn detects_lit_travel_to_a_paths_start() {
    let found = assert_reported(
        &line_from_home(),
        ViolationKind::LitTravel,
        &["first point"],
    );
    assert_eq!(found.len(), 1);
    assert_eq!(found[0].t_us, 0);
}

#[test]
#[ignore = "enable after merging the travel fix (issue 9 item 11)"]
fn holds_after_dark_travel() {
    assert_safe_allowing(&line_from_home(), UNTIL_STEP_FIXES);
}

// What holds today.

#[test]
fn a_gimbal_pattern_in_dwell_mode_is_safe() {
    assert_safe_allowing(
        &run_with(
            "laser dwell\nset dwell_ms 50\npattern corner once\nwait 1000\n@button\nwait 100\nstatus\n",
            SimOptions::default(),
        ),
        UNTIL_STEP_FIXES,
    );
}

#[test]
fn a_galvo_pattern_that_completes_is_safe() {
    assert_safe_allowing(
        &run_with(
            "target galvo\nset dwell_ms 20\npattern visit-all once\nwait 900\npattern tuning 0 0 5 once\nwait 500\n",
            SimOptions::default(),
        ),
        UNTIL_STEP_FIXES,
    );
}
