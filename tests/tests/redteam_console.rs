//! Red-team variations on issue 9 defect 4: a host that stops reading
//! must not be able to hold back a `stop` it typed.

use laser_sim::world::{SimOptions, SimReport};
use system_tests::{run_with, sent_at};

/// Time from `t_us` to the gimbal laser's next switch-off, µs (the laser
/// was on just before `t_us`: a stop typed may darken it at that instant).
fn lit_gimbal_dark_after(report: &SimReport, t_us: u64) -> u64 {
    assert!(
        report.recording.laser_at(t_us.saturating_sub(1)),
        "lit when stop was typed"
    );
    system_tests::gimbal_dark_after(report, t_us)
}

/// Last lit galvo sample at or after `t_us`, µs after it (0: none).
fn galvo_lit_after(report: &SimReport, t_us: u64) -> u64 {
    report
        .dac
        .iter()
        .filter(|(t, s)| s.laser && *t >= t_us * 1000)
        .map(|(t, _)| t / 1000 - t_us)
        .last()
        .unwrap_or(0)
}

#[test]
fn stop_typed_right_after_data_commands_of_a_stalled_host_is_not_held_back() {
    // The console gives earlier output 250 ms to reach the host before
    // each command with data lines. With the host not reading, `stop`
    // typed behind N `params` waited (N − 1) × 250 ms: the laser stayed
    // lit 1.75 s after `stop` with N = 8 (issue 9: "no console
    // back-pressure may ever delay the safety path").
    for typed_ahead in [2, 4, 8] {
        for (target, pattern) in [("gimbal", "visit-all"), ("galvo", "tuning")] {
            let mut script = format!(
                "target {target}\nset dwell_ms 1000\npattern {pattern}\nwait 1000\n@stall-read 5000\n"
            );
            for _ in 0..typed_ahead {
                script.push_str("@type-ahead params\n");
            }
            script.push_str("stop\nwait 6000\n");
            let report = run_with(&script, SimOptions::default());
            assert!(report.transcript.script_done, "{script}");
            let stop_us = sent_at(&report, "stop");
            let late_us = if target == "gimbal" {
                lit_gimbal_dark_after(&report, stop_us)
            } else {
                galvo_lit_after(&report, stop_us)
            };
            eprintln!("{target}, {typed_ahead} params typed ahead: dark {late_us} µs after stop");
            assert!(
                late_us <= 255_000,
                "{target}: {typed_ahead} `params` typed ahead of `stop` by a host not reading: \
                 lit {late_us} µs after `stop`"
            );
        }
    }
}

#[test]
fn stop_typed_behind_a_flood_of_refused_lines_by_a_stalled_host_is_not_held_back() {
    for flood in [300, 1500] {
        let mut script =
            String::from("set dwell_ms 5000\npattern visit-all\nwait 2000\n@stall-read 5000\n");
        for _ in 0..flood {
            script.push_str("@type-ahead bogus\n");
        }
        script.push_str("stop\nwait 6000\n");
        let report = run_with(&script, SimOptions::default());
        assert!(report.transcript.script_done);
        let stop_us = sent_at(&report, "stop");
        let dark_us = lit_gimbal_dark_after(&report, stop_us);
        eprintln!("{flood} refused lines typed ahead: dark {dark_us} µs after stop");
        // Every line still gets exactly one closer, in order: the lines
        // that found the output queue full are refused, their `stop` says ok.
        let lines = &report.transcript.lines;
        let sent = lines.iter().filter(|(_, l)| l.starts_with("> ")).count();
        let closers: Vec<&str> = lines
            .iter()
            .map(|(_, l)| l.as_str())
            .filter(|l| *l == "ok" || l.starts_with("error:"))
            .collect();
        assert_eq!(closers.len(), sent, "one closer per line");
        assert_eq!(closers.last(), Some(&"ok"), "the stop's closer comes last");
        assert!(
            dark_us <= 255_000,
            "{flood} refused lines typed ahead of `stop` by a host not reading: \
             lit {dark_us} µs after `stop`"
        );
    }
}
