//! The known defects of issue 9 under the safety checker
//! (`laser_sim::safety`): each reproducer from the issue runs in the
//! simulator and must hold every invariant now that the defects are fixed.
//! Before the fixes were merged, the checker reported each of them on
//! these same scenarios (the `detects_…` tests in the history of the
//! `checker` branch): the galvo lit for seconds after `stop` (item 1),
//! buffered halves lit after stop, the button, a servo fault or a target
//! switch (item 2), lit underrun replays (item 3), a 12 ms path check
//! (item 5), lit travel on a dead servo (item 6) and to a path's start
//! (item 11).
//!
//! Long task steps are tolerated (`UNTIL_STEP_FIXES`) except where they
//! are the point: one noisy poll on a loaded machine must not fail a
//! laser-safety test.

use laser_sim::servo_port::{BusFaults, SilentWindow};
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{
    UNTIL_STEP_FIXES, assert_safe, assert_safe_allowing, run_with, run_with_galvo_cost,
};

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
fn holds_after_the_master_laser_gate_on_a_servo_fault() {
    assert_safe_allowing(&servo_fault_while_the_galvo_dwells(), UNTIL_STEP_FIXES);
}

// Item 3: an underrun replays stale halves lit; the laser stays lit
// ~2.5 ms after the loop learned of it.

fn slow_galvo_loop(cost_ns_per_sample: u64) -> SimReport {
    run_with_galvo_cost(
        "target galvo\nset dwell_ms 5\npattern corner\nwait 300\n",
        cost_ns_per_sample,
    )
}

#[test]
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
fn holds_after_incremental_path_checks() {
    // A long step must recur in every run (see `steady_steps`).
    let report = system_tests::steady_steps(fine_line);
    assert_safe(&report);
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
