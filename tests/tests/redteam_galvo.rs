//! Red-team variations on the galvo (issue 9 defects 1–3, 5 and SPEC §9's
//! step-time rule) that the fixes' own tests did not try.

use laser_sim::world::SimOptions;
use system_tests::{lit_sample_times_ns, run_with, run_with_galvo_cost};

/// Longest firmware task step (host CPU) of a run with two 160 mm galvo
/// jumps at sample period `ts_us` with `planner`, counting only long steps
/// that recur in every run (see `steady_steps`), µs.
fn longest_poll_of_jumps(ts_us: u32, planner: &str) -> u128 {
    let script = format!(
        "target galvo\nplanner {planner}\nset galvo.ts_us {ts_us}\nwait 50\n\
         goto 8 5\nwait 100\ngoto -8 -5\nwait 100\nstop\n"
    );
    let report = system_tests::steady_steps(|| run_with(&script, SimOptions::default()));
    assert!(report.succeeded(false), "{:?}", report.transcript);
    laser_sim::executor::longest_firmware_step(&report.task_steps).as_micros()
}

#[test]
fn a_galvo_jump_is_planned_without_holding_the_executor_at_any_sample_period() {
    // SPEC §9: no task step holds the executor for more than 1 ms (on the
    // target; the host is 30–60× faster at f64). At the default 10 µs
    // the jump plans in ~70 µs; at 53 µs the same jumps took 2.6 ms in one
    // poll. Long steps count only when they recur in every run (host
    // load inflates a poll now and then, never the same one each time).
    let mut worst = (0, 0);
    for ts_us in [10, 23, 35, 53, 71, 86, 116] {
        let longest = longest_poll_of_jumps(ts_us, "optimal");
        eprintln!("ts {ts_us} µs: longest poll {longest} µs");
        if longest > worst.1 {
            worst = (ts_us, longest);
        }
    }
    assert!(
        worst.1 <= 1_000,
        "at galvo.ts_us {} one executor poll took {} µs of host CPU",
        worst.0,
        worst.1
    );
}

#[test]
fn laser_off_darkens_the_galvo_at_once_at_any_sample_period() {
    // `laser off` used to reach only the halves computed after it: the
    // two already handed to the DAC and the one waiting for its slot kept
    // the galvo lit for up to three half buffers (2.7 ms at 10 µs per
    // sample, 31 ms at 100 µs, 324 ms at 1 ms). The mirrors still draw,
    // dark; `laser auto` lights the run again.
    for ts_us in [10, 100, 1000] {
        let script = format!(
            "target galvo\nset galvo.ts_us {ts_us}\nset dwell_ms 2000\npattern corner once\n\
             wait 700\nlaser off\nwait 1000\nlaser auto\nwait 3000\nstop\n"
        );
        let report = run_with(&script, SimOptions::default());
        assert!(report.succeeded(false), "{:?}", report.transcript);
        let off_ns = system_tests::sent_at(&report, "laser off") * 1000;
        let auto_ns = system_tests::sent_at(&report, "laser auto") * 1000;
        let lit = lit_sample_times_ns(&report);
        assert!(lit.iter().any(|&t| t < off_ns), "ts {ts_us}: lit before");
        let late: Vec<u64> = lit
            .iter()
            .filter(|&&t| t >= off_ns && t < auto_ns)
            .map(|t| (t - off_ns) / 1000)
            .collect();
        assert!(
            late.is_empty(),
            "ts {ts_us} µs: {} lit samples after `laser off`, the last {} µs after it",
            late.len(),
            late.last().unwrap_or(&0)
        );
        assert!(
            lit.iter().any(|&t| t > auto_ns),
            "ts {ts_us}: lit again after laser auto"
        );
    }
}

#[test]
fn laser_dwell_keeps_galvo_marking_dark_like_the_gimbal() {
    // `laser dwell` = lit only while dwelling. The gimbal draws a circle
    // dark in that mode; the galvo used to mark it lit (32 831 lit
    // samples for `pattern circle 0 0 5 once`), also after `laser dwell`
    // was typed mid-path.
    let report = run_with(
        "target galvo\nlaser dwell\npattern circle 0 0 5 once\nwait 1000\n",
        SimOptions::default(),
    );
    assert!(report.succeeded(false), "{:?}", report.transcript);
    let lit = report.dac.iter().filter(|(_, s)| s.laser).count();
    assert_eq!(lit, 0, "lit samples marking a circle in laser dwell mode");

    for ts_us in [10, 1000] {
        let report = run_with(
            &format!(
                "target galvo\nset galvo.ts_us {ts_us}\npattern circle 0 0 5\nwait 150\n\
                 laser dwell\nwait 1000\nlaser auto\nwait 1000\nstop\n"
            ),
            SimOptions::default(),
        );
        assert!(report.succeeded(false), "{:?}", report.transcript);
        let dwell_ns = system_tests::sent_at(&report, "laser dwell") * 1000;
        let auto_ns = system_tests::sent_at(&report, "laser auto") * 1000;
        let lit = lit_sample_times_ns(&report);
        assert!(lit.iter().any(|&t| t < dwell_ns), "ts {ts_us}: lit before");
        let late = lit
            .iter()
            .filter(|&&t| t >= dwell_ns && t < auto_ns)
            .count();
        assert_eq!(late, 0, "ts {ts_us} µs: lit samples after `laser dwell`");
        assert!(lit.iter().any(|&t| t > auto_ns), "ts {ts_us}: lit again");
    }

    // Grid points still light while dwelling.
    let report = run_with(
        "target galvo\nlaser dwell\nset dwell_ms 20\npattern corner once\nwait 200\n",
        SimOptions::default(),
    );
    assert!(report.succeeded(false), "{:?}", report.transcript);
    let lit = report.dac.iter().filter(|(_, s)| s.laser).count();
    assert_eq!(lit, 4 * 2000, "four 20 ms dwells lit");
}

#[test]
#[ignore = "redteam: at 5 ms of loop time per sample (a sample costs more than a whole 1.28 ms half) a goto stopped at 100 ms gives 11 underrun notices, 10 of them while the loop is idle again after the stop"]
fn an_idle_galvo_loop_never_underruns_after_a_job_however_slow() {
    for cost_ns in [1_300_000, 2_000_000, 5_000_000] {
        let report = run_with_galvo_cost(
            "target galvo\ngoto 1 1\nwait 100\nstop\nwait 5000\n",
            cost_ns,
        );
        let notices: Vec<&String> = report
            .transcript
            .notices
            .iter()
            .map(|(_, n)| n)
            .filter(|n| n.contains("underrun"))
            .collect();
        // The job itself may underrun once; the idle loop after it never.
        assert!(
            notices.len() <= 1,
            "{cost_ns} ns per sample: {} underrun notices: {notices:?}",
            notices.len()
        );
    }
}

#[test]
fn an_underrun_is_told_with_the_stop_it_makes_never_after_it() {
    // Issue 25, defect 9: at 15 µs of compute per sample the pattern
    // underran and stopped (told), then the parked loop underran again
    // and a second notice said "stopped" of a pattern stopped before.
    let report = run_with_galvo_cost(
        "target galvo\npattern tuning\nwait 500\nstop\nwait 500\npattern tuning\nwait 500\n",
        15_000,
    );
    assert!(
        report.galvo_underruns >= 3,
        "the loop underran while parked too: {}",
        report.galvo_underruns
    );
    let told: Vec<u64> = report
        .transcript
        .notices
        .iter()
        .filter(|(_, n)| n.contains("galvo underrun"))
        .map(|(t, _)| *t)
        .collect();
    let second_start = report
        .transcript
        .lines
        .iter()
        .filter(|(_, l)| l == "> pattern tuning")
        .nth(1)
        .map(|(t, _)| *t)
        .expect("the pattern was started twice");
    assert_eq!(told.len(), 2, "one notice per pattern stopped: {told:?}");
    assert!(told[0] < 500_000 && told[1] >= second_start, "{told:?}");
}
