//! Laser power (issue 12) in the simulator: G-code's S on the gimbal's
//! laser output as a duty (recorded per mille), M3 / M4, the power
//! overrides on the fly with `FS:` / `Ov:`, clamping, the gate forcing the
//! duty to 0, and the galvo's laser staying on/off.

use laser_sim::world::{SimOptions, SimReport};
use system_tests::{UNTIL_STEP_FIXES, assert_safe_allowing, run_with, terminal_lines};

/// Runs `script` on the simulator, checked by the safety checker.
fn run(script: &str) -> SimReport {
    let report = run_with(script, SimOptions::default());
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    report
}

/// How long the gimbal laser ran at each level, µs, by level (‰).
fn time_at_levels(report: &SimReport) -> Vec<(u16, u64)> {
    let changes = &report.recording.laser_power;
    let mut levels: Vec<(u16, u64)> = Vec::new();
    for (k, &(t, level)) in changes.iter().enumerate() {
        let until = changes.get(k + 1).map_or(report.end_time_us, |c| c.0);
        match levels.iter_mut().find(|(l, _)| *l == level) {
            Some((_, total)) => *total += until - t,
            None => levels.push((level, until - t)),
        }
    }
    levels
}

/// Time the gimbal laser ran at `level` ‰, µs.
fn time_at(report: &SimReport, level: u16) -> u64 {
    time_at_levels(report)
        .iter()
        .find(|(l, _)| *l == level)
        .map_or(0, |(_, t)| *t)
}

/// The status reports (`<…>`) of the transcript.
fn reports(report: &SimReport) -> Vec<&str> {
    terminal_lines(report)
        .into_iter()
        .filter(|l| l.starts_with('<'))
        .collect()
}

#[test]
fn m3_s300_and_s1000_record_duties_of_30_and_100_percent() {
    let report = run("$30=1000\n$31=0\n\
         G0 X-20 Y0\n\
         G1 X0 F600 M3 S300\n\
         G1 X20 S1000\n\
         G1 X25 S2500\n\
         M5\n");
    let levels = time_at_levels(&report);
    eprintln!("time at levels (‰, µs): {levels:?}");
    // 20 mm at each level.
    assert!(time_at(&report, 300) > 700_000, "{levels:?}");
    assert!(time_at(&report, 1000) > 700_000, "{levels:?}");
    assert!(
        levels.iter().all(|&(l, _)| l == 0 || l == 300 || l == 1000),
        "S2500 clamps to full, nothing else lights: {levels:?}"
    );
    // The trace and the SVG carry the level.
    let trace = report.recording.trace_csv();
    assert!(trace.starts_with("t_ms,x_cm,y_cm,laser,power\n"));
    assert!(
        trace.lines().any(|l| l.ends_with(",1,300")),
        "a sample at 30 %"
    );
    assert_eq!(report.recording.power_at(report.end_time_us), 0, "M5: dark");
}

#[test]
fn power_overrides_change_the_recorded_power_mid_job_and_the_status_shows_them() {
    let report = run("G0 X-40 Y0\n\
         G1 X40 F600 M3 S500\n\
         wait 800\n\
         @realtime ?\n\
         @realtime ?\n\
         @realtime 0x9b\n\
         @realtime 0x9d\n\
         wait 800\n\
         @realtime ?\n\
         @realtime ?\n\
         @realtime 0x99\n\
         @realtime 0x9a\n\
         @realtime 0x9c\n\
         wait 800\n\
         @realtime ?\n\
         @realtime ?\n\
         wait 3000\n");
    let levels = time_at_levels(&report);
    eprintln!("time at levels (‰, µs): {levels:?}");
    // S500 → −10 % −1 % = 89 % → 445 ‰; reset +10 % +1 % = 111 % → 555 ‰.
    for level in [500, 445, 555] {
        assert!(time_at(&report, level) > 400_000, "{level}: {levels:?}");
    }
    let reports = reports(&report);
    eprintln!("{reports:#?}");
    let shows = |text: &str| reports.iter().any(|r| r.contains(text));
    assert!(shows("|FS:600,500"), "before the overrides");
    assert!(
        shows("|FS:600,445") && shows("|Ov:100,100,89"),
        "after −11 %"
    );
    assert!(
        shows("|FS:600,555") && shows("|Ov:100,100,111"),
        "after +11 %"
    );
}

#[test]
fn m4_on_the_gimbal_runs_below_s_where_the_servos_limit_the_speed_and_dark_at_rest() {
    let fast = run("G0 X-20 Y0\nG1 X20 F60000 M4 S1000\nG1 X-20\n");
    let levels = time_at_levels(&fast);
    eprintln!("M4 at F60000: {levels:?}");
    let lit: Vec<_> = levels.iter().filter(|(l, _)| *l > 0).collect();
    assert!(!lit.is_empty(), "M4 lights while moving");
    assert!(
        lit.iter().all(|(l, _)| *l < 1000),
        "the servo-limited speed is below F: {levels:?}"
    );
    // Between the two blocks the gimbal settles at rest: M4 is dark there
    // (two separate lit spans), where M3 stays lit.
    let lit_spans = |r: &SimReport| r.recording.laser_events.iter().filter(|e| e.1).count();
    assert!(lit_spans(&fast) >= 2, "{:?}", fast.recording.laser_events);
    let m3 = run("G0 X-20 Y0\nG1 X20 F60000 M3 S1000\nG1 X-20\n");
    assert_eq!(lit_spans(&m3), 1, "{:?}", m3.recording.laser_events);
    assert!(time_at(&m3, 1000) > 0);
}

#[test]
fn stop_reset_and_the_button_force_the_duty_to_0_at_once() {
    for (how, script) in [
        ("stop", "stop\n"),
        ("soft reset", "@realtime 0x18\n"),
        ("feed hold", "@realtime !\n"),
        ("button", "@button\n"),
    ] {
        let report = run(&format!(
            "G0 X-20 Y0\nG1 X20 F600 M3 S400\nwait 1000\n{script}wait 500\n"
        ));
        // The trigger goes out 1 s after the G1's `ok`.
        let (ok_at, reply) = system_tests::reply_to(&report, "G1 X20 F600 M3 S400");
        assert_eq!(reply, "ok");
        let stopped_at = system_tests::sent_at(&report, "G1 X20 F600 M3 S400") + ok_at + 1_000_000;
        assert_eq!(
            report.recording.power_at(stopped_at - 1),
            400,
            "{how}: lit before"
        );
        let dark = report
            .recording
            .laser_power
            .iter()
            .find(|&&(t, level)| t >= stopped_at && level == 0)
            .map(|(t, _)| t - stopped_at);
        eprintln!("{how}: duty 0 after {dark:?} µs");
        assert!(dark.is_some_and(|us| us <= 1000), "{how}: {dark:?}");
        assert_eq!(report.recording.power_at(report.end_time_us), 0, "{how}");
    }
}

#[test]
fn the_galvo_marks_on_or_off_whatever_s() {
    let report = run("target galvo\nG0 X-10 Y0\nG1 X10 F600 M3 S300\nG1 X-10 S1000\nM5\n");
    let lit = report.dac.iter().filter(|(_, s)| s.laser).count();
    assert!(lit > 0, "S300 marks");
    assert!(
        report.recording.laser_power.iter().all(|(_, l)| *l == 0),
        "the gimbal's output stays dark: {:?}",
        report.recording.laser_power
    );
}
