//! G-code through the simulated console: grbl's replies, the motion
//! queue, and what the gimbal and the galvo draw for a realistic laser job.

use laser_sim::world::{SimOptions, SimReport};
use system_tests::gcode_job::{Job, PathFit, SpotMm, fit, laser_job, rapids_dark};
use system_tests::gcode_toolpath::{galvo_spot_mm, gimbal_spot_mm, lit_mm};
use system_tests::{
    UNTIL_STEP_FIXES, assert_all_ok, assert_safe_allowing, run_with, script, terminal_lines,
};

/// Servo resolution, 0.1°, as a distance on the board at the gimbal's
/// distance (OQ = 25 cm) and the job's far corner (~50 mm off centre):
/// 250 mm × tan(0.1°) × (1 + (50/250)²) ≈ 0.45 mm.
const GIMBAL_TOLERANCE_MM: f64 = 0.45;
/// The galvo's tolerance (issue 12).
const GALVO_TOLERANCE_MM: f64 = 0.2;

/// Every G0 of `job` was found on the spot's timeline, crossed with at
/// least one sample, and not one of them lit.
fn assert_dark_on_every_rapid(samples: &[SpotMm], job: &Job, tol_mm: f64, label: &str) {
    let spans =
        rapids_dark(samples, &job.rapids, tol_mm).unwrap_or_else(|e| panic!("{label}: {e}"));
    assert_eq!(spans.len(), job.rapids.len(), "{label}: {spans:?}");
    for (k, span) in spans.iter().enumerate() {
        assert!(span.samples > 0, "{label}: G0 #{k} not sampled: {span:?}");
        assert_eq!(span.lit, 0, "{label}: lit during G0 #{k}: {span:?}");
    }
    eprintln!(
        "{label}: {} G0s dark over {} samples",
        spans.len(),
        spans.iter().map(|s| s.samples).sum::<usize>()
    );
}

#[test]
fn a_laser_job_draws_its_toolpath_on_the_gimbal() {
    let job = laser_job(40.0);
    let report = run_with(&script("", &job.lines), SimOptions::default());
    assert_all_ok(&report, "gimbal");
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    let PathFit {
        worst_lit_mm,
        worst_missed_mm,
        lit,
        ..
    } = fit(&lit_mm(&gimbal_spot_mm(&report)), &job.pieces);
    eprintln!(
        "gimbal: {lit} lit samples, worst off path {worst_lit_mm:.3} mm, worst gap {worst_missed_mm:.3} mm, {:.1} s",
        report.end_time_us as f64 / 1e6
    );
    assert!(
        worst_lit_mm <= GIMBAL_TOLERANCE_MM,
        "lit {worst_lit_mm:.3} mm off the toolpath"
    );
    assert!(
        worst_missed_mm <= 1.5,
        "toolpath missed by {worst_missed_mm:.3} mm"
    );
    assert_dark_on_every_rapid(
        &gimbal_spot_mm(&report),
        &job,
        GIMBAL_TOLERANCE_MM,
        "gimbal",
    );
}

#[test]
fn a_laser_job_draws_its_toolpath_on_the_galvo() {
    let job = laser_job(25.0);
    let report = run_with(&script("target galvo\n", &job.lines), SimOptions::default());
    assert_all_ok(&report, "galvo");
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    let PathFit {
        worst_lit_mm,
        worst_missed_mm,
        lit,
        ..
    } = fit(&lit_mm(&galvo_spot_mm(&report)), &job.pieces);
    eprintln!(
        "galvo: {lit} lit samples, worst off path {worst_lit_mm:.3} mm, worst gap {worst_missed_mm:.3} mm, {:.1} s",
        report.end_time_us as f64 / 1e6
    );
    assert!(
        worst_lit_mm <= GALVO_TOLERANCE_MM,
        "lit {worst_lit_mm:.3} mm off the toolpath"
    );
    assert!(
        worst_missed_mm <= 0.5,
        "toolpath missed by {worst_missed_mm:.3} mm"
    );
    assert_dark_on_every_rapid(&galvo_spot_mm(&report), &job, GALVO_TOLERANCE_MM, "galvo");
}

/// The reply closing `line` (the first `ok` / `error…` after it).
fn closer_of<'a>(lines: &[&'a str], line: &str) -> &'a str {
    let sent = lines
        .iter()
        .position(|l| l.strip_prefix("> ") == Some(line))
        .unwrap_or_else(|| panic!("{line:?} not sent"));
    lines[sent..]
        .iter()
        .find(|l| **l == "ok" || l.starts_with("error"))
        .unwrap_or_else(|| panic!("no reply to {line:?}"))
}

#[test]
fn every_grbl_error_the_controller_emits_is_provoked() {
    // (line, grbl error number); `$X` between lines that lock.
    let cases: &[(&str, u8)] = &[
        ("G1 #1", 1),
        ("G1 X", 2),
        ("$Q", 3),
        ("G1 X1 F-5", 4),
        ("$J=G1 X1 F10", 16),
        ("$J=G91 X200 F100", 15),
        ("G5 X1", 20),
        ("M100", 20),
        ("G0 G1 X1", 21),
        ("G1 X1", 22),
        ("M3.5", 23),
        ("G1 G92 X1 F10", 24),
        ("G0 X1 X2", 25),
        ("G92", 26),
        ("N10000000 G0 X0", 27),
        ("G4", 28),
        ("G10 L2 P2 X1", 29),
        ("G55", 29),
        ("G2 G53 X1 Y1 I1 F100", 30),
        ("G80 X1", 31),
        ("G2 Z1 I1 F100", 32),
        ("G2 X10 Y0 I1 J0 F100", 33),
        ("G2 X10 R1 F100", 34),
        ("G2 X10 F100", 35),
        ("G0 X1 P2", 36),
        ("T300", 38),
    ];
    let mut text = String::from("G80\n");
    for (line, _) in cases {
        text.push_str(line);
        text.push('\n');
        // Leave the modal state as it was (G80 for the 31 case).
        text.push_str("G0\n");
    }
    // error:8 ($C while a move runs) and error:9 (G-code in alarm).
    text.push_str("G1 X20 F300\n$C\nG0 X5000\nG0 X1\n$X\nG0 X0\n");
    let report = run_with(&text, SimOptions::default());
    let lines = terminal_lines(&report);
    for (line, code) in cases {
        assert_eq!(closer_of(&lines, line), format!("error:{code}"), "{line}");
    }
    assert_eq!(closer_of(&lines, "$C"), "error:8");
    // Soft limit: ALARM:2, then G-code locked until $X.
    let alarm = lines.iter().position(|l| *l == "ALARM:2").expect("ALARM:2");
    assert_eq!(lines[alarm - 1], "> G0 X5000", "{lines:?}");
    assert_eq!(closer_of(&lines, "G0 X1"), "error:9");
    assert_eq!(closer_of(&lines, "$X"), "ok");
    assert!(lines.contains(&"[MSG:Caution: Unlocked]"));
    assert_eq!(closer_of(&lines, "G0 X0"), "ok");
}

#[test]
fn feed_hold_stops_dark_and_resume_finishes_the_job() {
    // A 60 mm lit line at 600 mm/min: 6 s. Hold after 2 s for 2 s.
    let text = "G0 X-30 Y0\nM3 S1000\nG1 X30 F600\nwait 2000\n!\nwait 300\n?\nwait 1700\n?\n~\nwait 200\n?\n";
    let report = run_with(text, SimOptions::default());
    let lines = terminal_lines(&report);
    let statuses: Vec<&&str> = lines.iter().filter(|l| l.starts_with('<')).collect();
    assert_eq!(statuses.len(), 3, "{lines:?}");
    assert!(statuses[0].starts_with("<Hold:0|MPos:"), "{statuses:?}");
    assert!(statuses[1].starts_with("<Hold:0|MPos:"), "{statuses:?}");
    assert!(statuses[2].starts_with("<Run|MPos:"), "{statuses:?}");
    // Dark from the hold (+1 ms) to the resume.
    let sent = |l: &str| system_tests::sent_at(&report, l);
    let hold_at = sent("!");
    let resume_at = sent("~");
    let lit_in_hold = report
        .recording
        .spot
        .iter()
        .any(|s| s.laser && s.t_us > hold_at + 1_000 && s.t_us < resume_at);
    assert!(!lit_in_hold, "lit during the hold");
    // The whole line was drawn all the same, and nothing else.
    let fit = fit(
        &lit_mm(&gimbal_spot_mm(&report)),
        &[system_tests::gcode_job::Piece::Line {
            a: [-30.0, 0.0],
            b: [30.0, 0.0],
        }],
    );
    assert!(fit.worst_lit_mm <= GIMBAL_TOLERANCE_MM, "{fit:?}");
    assert!(fit.worst_missed_mm <= 1.5, "{fit:?}");
    assert!(report.idle_at_end);
}

#[test]
fn soft_reset_during_motion_raises_alarm_3_and_keeps_settings() {
    let text = "$32=1\ntarget gimbal\nG0 X-30\nM3 S1000\nG1 X30 F600\nwait 1000\n\u{18}\nG0 X0\n$X\n$$\n?\n";
    let report = run_with(text, SimOptions::default());
    let lines = terminal_lines(&report);
    let alarm = lines.iter().position(|l| *l == "ALARM:3").expect("ALARM:3");
    assert_eq!(lines[alarm + 1], "Grbl 1.1h ['$' for help]", "{lines:?}");
    assert!(lines.contains(&"[MSG:'$H'|'$X' to unlock]"));
    assert_eq!(closer_of(&lines, "G0 X0"), "error:9");
    assert!(lines.contains(&"$32=1"));
    let reset_at = report
        .transcript
        .lines
        .iter()
        .find(|(_, l)| l == "ALARM:3")
        .map(|(t, _)| *t)
        .unwrap();
    let lit_after = report
        .recording
        .laser_events
        .iter()
        .filter(|(t, _)| *t >= reset_at)
        .any(|(_, on)| *on);
    assert!(!lit_after, "lit after the reset");
    let last_status = lines.iter().rev().find(|l| l.starts_with('<')).unwrap();
    assert!(last_status.starts_with("<Idle|MPos:"), "{last_status}");
}

#[test]
fn feed_hold_on_the_galvo_is_dark_and_the_job_still_draws_its_toolpath() {
    let job = laser_job(25.0);
    // Hold after 40 lines (16 blocks queued ahead), resume 500 ms later.
    let mut lines = job.lines.clone();
    lines.insert(40, "!".into());
    lines.insert(41, "wait 500".into());
    lines.insert(42, "?".into());
    lines.insert(43, "~".into());
    let report = run_with(&script("target galvo\n", &lines), SimOptions::default());
    assert_all_ok(&report, "galvo hold");
    let hold_us = system_tests::sent_at(&report, "!");
    let resume_us = system_tests::sent_at(&report, "~");
    let lit_in_hold: Vec<u64> = system_tests::lit_sample_times_ns(&report)
        .into_iter()
        .filter(|&t| t > (hold_us + 1_000) * 1_000 && t < resume_us * 1_000)
        .collect();
    assert!(
        lit_in_hold.is_empty(),
        "{} lit samples in the hold",
        lit_in_hold.len()
    );
    let status = terminal_lines(&report)
        .into_iter()
        .find(|l| l.starts_with('<'))
        .expect("a status report");
    assert!(status.starts_with("<Hold:0|"), "{status}");
    let fit = fit(&lit_mm(&galvo_spot_mm(&report)), &job.pieces);
    assert!(fit.worst_lit_mm <= GALVO_TOLERANCE_MM, "{fit:?}");
    assert!(fit.worst_missed_mm <= 0.5, "{fit:?}");
}

#[test]
fn an_over_long_gcode_line_is_grbl_error_11_and_a_product_line_keeps_its_error() {
    let long_gcode = format!("G1 X1 F100 ({})", "x".repeat(200));
    let long_product = format!("goto {}", "1".repeat(200));
    let text = format!("{long_gcode}\n{long_product}\nG0 X1\n");
    let report = run_with(&text, SimOptions::default());
    let lines = terminal_lines(&report);
    let replies: Vec<&&str> = lines
        .iter()
        .filter(|l| *l == &"ok" || l.starts_with("error"))
        .collect();
    assert_eq!(
        replies,
        [&"error:11", &"error: line too long (max 128 bytes)", &"ok"],
        "{lines:?}"
    );
    assert!(report.idle_at_end);
}

/// Time the galvo laser was lit from first to last lit sample, s.
fn galvo_lit_span_s(report: &SimReport) -> f64 {
    let lit = system_tests::lit_sample_times_ns(report);
    let (first, last) = (lit.first().expect("lit"), lit.last().expect("lit"));
    (last - first) as f64 / 1e9
}

#[test]
fn the_galvo_marks_at_the_programmed_feed() {
    // A 40 mm line at 600 and at 1200 mm/min: 4 s and 2 s.
    let mark = |feed: u32| {
        let text = format!("target galvo\nG0 X-20 Y5\nG1 X20 F{feed} M3 S1000\nM5\nG0 X0 Y0\n");
        let report = run_with(&text, SimOptions::default());
        assert_all_ok(&report, "galvo feed");
        let fit = fit(
            &lit_mm(&galvo_spot_mm(&report)),
            &[system_tests::gcode_job::Piece::Line {
                a: [-20.0, 5.0],
                b: [20.0, 5.0],
            }],
        );
        assert!(fit.worst_lit_mm <= GALVO_TOLERANCE_MM, "{fit:?}");
        galvo_lit_span_s(&report)
    };
    let (slow, fast) = (mark(600), mark(1200));
    eprintln!("galvo: 40 mm at F600 {slow:.3} s, at F1200 {fast:.3} s");
    assert!((slow - 4.0).abs() < 0.05, "F600: {slow} s");
    assert!((fast - 2.0).abs() < 0.05, "F1200: {fast} s");
}
