//! G-code jobs of many short blocks through the look-ahead planner, in the
//! simulator: a 200-segment circle and a sharp zig-zag on the gimbal
//! (continuous across gentle junctions, slower at sharp corners, on the
//! toolpath within the servo resolution) and on the stepper (within its
//! tolerance, clean pulses, no stall); a feed hold mid-job decelerates and
//! resumes on the path; `?` answers Run / Hold throughout.

use laser_sim::world::{SimOptions, SimReport};
use system_tests::gcode_job::{Piece, fit};
use system_tests::gcode_toolpath::{gimbal_spot_mm, lit_mm};
use system_tests::{assert_all_ok, run_with, script, sent_at, terminal_lines};

/// Servo resolution on the board (see `gcode_sim.rs`), mm.
const GIMBAL_TOLERANCE_MM: f64 = 0.45;
/// The stepper's: its line cut (0.05 mm) + one microstep of spot travel
/// at the board (≤ 0.3 mm at 25 cm, see `stepper_sim.rs`), mm.
const STEPPER_TOLERANCE_MM: f64 = 0.35;
/// Feed of the jobs, mm/min.
const FEED_MM_MIN: f64 = 1200.0;

/// A lit polyline job: rapid to `at(0)`, then G1 through `at(1)` ..
/// `at(n)` at the job's feed; its G-code lines, pieces and length (mm).
fn polyline_job(n: usize, at: impl Fn(usize) -> [f64; 2]) -> (Vec<String>, Vec<Piece>, f64) {
    let mut lines = vec![
        "G21 G90".to_string(),
        format!("G0 X{:.3} Y{:.3}", at(0)[0], at(0)[1]),
        "M3 S1000".to_string(),
        format!("G1 F{FEED_MM_MIN}"),
    ];
    let mut pieces = Vec::new();
    let mut length = 0.0;
    for k in 1..=n {
        let (a, b) = (at(k - 1), at(k));
        lines.push(format!("G1 X{:.3} Y{:.3}", b[0], b[1]));
        pieces.push(Piece::Line { a, b });
        length += (b[0] - a[0]).hypot(b[1] - a[1]);
    }
    lines.push("M5".to_string());
    (lines, pieces, length)
}

/// A closed polygon of `n` G1 segments approximating a circle of
/// `radius_mm` about the origin, and its pieces.
fn circle_job(n: usize, radius_mm: f64) -> (Vec<String>, Vec<Piece>, f64) {
    polyline_job(n, |k| {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        [radius_mm * a.cos(), radius_mm * a.sin()]
    })
}

/// A zig-zag of `n` segments between y = ±`half_height_mm`, x advancing
/// by `pitch_mm` (corners of ≈ 170°), and its pieces.
fn zigzag_job(n: usize, pitch_mm: f64, half_height_mm: f64) -> (Vec<String>, Vec<Piece>, f64) {
    let x0 = -pitch_mm * n as f64 / 2.0;
    polyline_job(n, |k| {
        let y = if k.is_multiple_of(2) {
            -half_height_mm
        } else {
            half_height_mm
        };
        [x0 + pitch_mm * k as f64, y]
    })
}

/// Simulated time from the first lit G1 to the end of the last lit
/// sample, s.
fn lit_span_s(report: &SimReport) -> f64 {
    let lit: Vec<u64> = report
        .recording
        .spot
        .iter()
        .filter(|s| s.laser)
        .map(|s| s.t_us)
        .collect();
    match (lit.first(), lit.last()) {
        (Some(a), Some(b)) => (b - a) as f64 / 1e6,
        _ => 0.0,
    }
}

/// Slowest spot speed over 200 ms windows of the lit path (the servo's
/// 0.1° steps need a few periods to average out), leaving out the first
/// and the last `margin_s`, mm/s.
fn slowest_lit_speed(report: &SimReport, margin_s: f64) -> f64 {
    let lit: Vec<(u64, [f64; 2])> = report
        .recording
        .spot
        .iter()
        .filter(|s| s.laser)
        .map(|s| (s.t_us, [s.x_cm * 10.0, s.y_cm * 10.0]))
        .collect();
    let (Some(first), Some(last)) = (lit.first(), lit.last()) else {
        return 0.0;
    };
    let margin = (margin_s * 1e6) as u64;
    let (from, to) = (first.0 + margin, last.0.saturating_sub(margin));
    let mut slowest = f64::INFINITY;
    let mut k = 0;
    for j in 0..lit.len() {
        while lit[j].0 - lit[k].0 > 200_000 {
            k += 1;
        }
        let (dt, a, b) = (lit[j].0 - lit[k].0, lit[k].1, lit[j].1);
        if lit[k].0 >= from && lit[j].0 <= to && dt >= 190_000 {
            let path: f64 = lit[k..=j]
                .windows(2)
                .map(|w| (w[1].1[0] - w[0].1[0]).hypot(w[1].1[1] - w[0].1[1]))
                .sum();
            let _ = (a, b);
            slowest = slowest.min(path / (dt as f64 / 1e6));
        }
    }
    slowest
}

/// Runs `lines` after `prefix`; returns the report and the job's time
/// from its first line to idle, s.
fn run_job(prefix: &str, lines: &[String]) -> (SimReport, f64) {
    let report = run_with(&script(prefix, lines), SimOptions::default());
    let start = sent_at(&report, &lines[0]);
    let seconds = (report.end_time_us - start) as f64 / 1e6;
    (report, seconds)
}

/// Runs a polyline job (see [`polyline_job`]) on the gimbal: no error,
/// every lit sample within the servo resolution of the path and the whole
/// path drawn. Returns the report, the lit time and the time the path
/// takes at the feed, s.
fn run_on_gimbal(label: &str, job: (Vec<String>, Vec<Piece>, f64)) -> (SimReport, f64, f64) {
    let (lines, pieces, length) = job;
    let (report, job_s) = run_job("", &lines);
    assert_all_ok(&report, label);
    let fit = fit(&lit_mm(&gimbal_spot_mm(&report)), &pieces);
    let at_feed_s = length / (FEED_MM_MIN / 60.0);
    let lit_s = lit_span_s(&report);
    eprintln!("{label}: job {job_s:.2} s, lit {lit_s:.2} s, at feed {at_feed_s:.2} s; {fit:?}");
    assert!(fit.worst_lit_mm <= GIMBAL_TOLERANCE_MM, "{label}: {fit:?}");
    assert!(fit.worst_missed_mm <= 1.5, "{label}: {fit:?}");
    (report, lit_s, at_feed_s)
}

#[test]
fn a_200_segment_circle_runs_continuously_on_the_gimbal() {
    // A stop and settle at each of the 200 blocks would take 8 s more.
    let (report, lit_s, at_feed_s) = run_on_gimbal("gimbal circle", circle_job(200, 40.0));
    // No stop at the gentle junctions: the lit part takes the time at
    // the feed (plus the start's and the end's ramps), far below one
    // settle per block.
    assert!(lit_s < at_feed_s * 1.1 + 0.3, "lit {lit_s:.2} s");
    // At the feed through the vertices: no 200 ms stretch slower than
    // 80 % of it (one stop and settle per 63 ms block would halve it).
    let slowest = slowest_lit_speed(&report, 0.3);
    eprintln!("gimbal circle: slowest 200 ms stretch {slowest:.1} mm/s");
    assert!(slowest > 0.8 * FEED_MM_MIN / 60.0, "{slowest}");
}

#[test]
fn a_sharp_zigzag_keeps_its_corners_on_the_gimbal() {
    let (_, lit_s, at_feed_s) = run_on_gimbal("gimbal zig-zag", zigzag_job(40, 4.0, 5.0));
    assert!(lit_s < at_feed_s * 1.2 + 0.3, "lit {lit_s:.2} s");
}

/// The circle with a hold inserted after its `at`-th line: `?` before,
/// during the hold and after `~`.
fn circle_with_hold(at: usize) -> (Vec<String>, Vec<Piece>) {
    let (mut lines, pieces, _) = circle_job(200, 40.0);
    let hold = [
        "?", "!", "wait 300", "?", "wait 700", "?", "~", "wait 100", "?",
    ];
    for (k, l) in hold.iter().enumerate() {
        lines.insert(at + k, l.to_string());
    }
    (lines, pieces)
}

/// The job's four `?` reports, checked to be Run, Hold:0, Hold:0, Run
/// (asked before the hold, twice in it, after the resume).
fn run_hold_hold_run_statuses(report: &SimReport) -> Vec<String> {
    let terminal = terminal_lines(report);
    let statuses: Vec<String> = terminal
        .iter()
        .filter(|l| l.starts_with('<'))
        .map(|l| l.to_string())
        .collect();
    assert_eq!(statuses.len(), 4, "{terminal:?}");
    for (status, state) in statuses
        .iter()
        .zip(["<Run|", "<Hold:0|", "<Hold:0|", "<Run|"])
    {
        assert!(status.starts_with(state), "{statuses:?}");
    }
    statuses
}

#[test]
fn a_hold_mid_job_decelerates_dark_and_resumes_on_the_path_on_the_gimbal() {
    let (lines, pieces) = circle_with_hold(60);
    let (report, _) = run_job("", &lines);
    assert_all_ok(&report, "gimbal hold");
    let statuses = run_hold_hold_run_statuses(&report);
    // Held where it stopped: both reports in the hold at one position.
    let mpos = |s: &str| s.split('|').nth(1).map(str::to_string);
    assert_eq!(mpos(&statuses[1]), mpos(&statuses[2]));
    let (hold_at, resume_at) = (sent_at(&report, "!"), sent_at(&report, "~"));
    let spot = &report.recording.spot;
    assert!(
        !spot
            .iter()
            .any(|s| s.laser && s.t_us > hold_at + 1_000 && s.t_us < resume_at),
        "lit during the hold"
    );
    // Stopped within a period or two of the hold (20 mm/s, braking at the
    // limit), then still until the resume.
    let at = |t: u64| {
        let s = spot.iter().rev().find(|s| s.t_us <= t).expect("a sample");
        [s.x_cm * 10.0, s.y_cm * 10.0]
    };
    let (a, b, c) = (at(hold_at), at(hold_at + 200_000), at(resume_at));
    let dist = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]);
    assert!(dist(a, b) < 1.5, "{a:?} {b:?}");
    assert!(dist(b, c) < 0.05, "{b:?} {c:?}");
    // The whole circle drawn, nothing off it.
    let fit = fit(&lit_mm(&gimbal_spot_mm(&report)), &pieces);
    assert!(fit.worst_lit_mm <= GIMBAL_TOLERANCE_MM, "{fit:?}");
    assert!(fit.worst_missed_mm <= 1.5, "{fit:?}");
}

/// The drivers saw clean pulses and no stall.
fn assert_clean_drive(report: &SimReport) {
    for axis in &report.stepper.axes {
        assert_eq!(
            axis.violations().total(),
            0,
            "{:?}\n{}",
            axis.violations(),
            report.stepper.report()
        );
        assert!(axis.stalls().is_empty(), "{}", report.stepper.report());
        assert_eq!(axis.lost_steps(), 0, "{}", report.stepper.report());
    }
}

#[test]
fn the_circle_and_the_zigzag_run_continuously_on_the_stepper() {
    for (name, (lines, pieces, length)) in [
        ("circle", circle_job(200, 40.0)),
        ("zig-zag", zigzag_job(40, 4.0, 5.0)),
    ] {
        // A dwell at the end lets the rotors settle before the run ends.
        let lines: Vec<String> = lines.into_iter().chain(["G4 P0.2".into()]).collect();
        let (report, job_s) = run_job("target stepper\n", &lines);
        assert_all_ok(&report, name);
        assert_clean_drive(&report);
        let fit = fit(&lit_mm(&gimbal_spot_mm(&report)), &pieces);
        let at_feed_s = length / (FEED_MM_MIN / 60.0);
        let lit_s = lit_span_s(&report);
        eprintln!(
            "stepper {name}: job {job_s:.2} s, lit {lit_s:.2} s, at feed {at_feed_s:.2} s; {fit:?}"
        );
        assert!(fit.worst_lit_mm <= STEPPER_TOLERANCE_MM, "{name}: {fit:?}");
        assert!(fit.worst_missed_mm <= 1.0, "{name}: {fit:?}");
        assert!(lit_s < at_feed_s * 1.1 + 0.3, "{name}: lit {lit_s:.2} s");
        if name == "circle" {
            let slowest = slowest_lit_speed(&report, 0.3);
            eprintln!("stepper circle: slowest 200 ms stretch {slowest:.1} mm/s");
            assert!(slowest > 0.8 * FEED_MM_MIN / 60.0, "{slowest}");
        }
    }
}

#[test]
fn a_hold_mid_job_decelerates_dark_and_resumes_on_the_path_on_the_stepper() {
    let (mut lines, pieces) = circle_with_hold(60);
    lines.push("G4 P0.2".into());
    let (report, _) = run_job("target stepper\n", &lines);
    assert_all_ok(&report, "stepper hold");
    assert_clean_drive(&report);
    run_hold_hold_run_statuses(&report);
    let (hold_at, resume_at) = (sent_at(&report, "!"), sent_at(&report, "~"));
    assert!(
        !report
            .recording
            .spot
            .iter()
            .any(|s| s.laser && s.t_us > hold_at + 1_000 && s.t_us < resume_at),
        "lit during the hold"
    );
    // At rest well before the resume, and on from exactly there.
    let spot = &report.recording.spot;
    let at = |t: u64| {
        let s = spot.iter().rev().find(|s| s.t_us <= t).expect("a sample");
        [s.x_cm * 10.0, s.y_cm * 10.0]
    };
    let dist = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]);
    let (a, b) = (at(hold_at + 400_000), at(resume_at));
    assert!(dist(a, b) < 1e-9, "{a:?} {b:?}");
    let fit = fit(&lit_mm(&gimbal_spot_mm(&report)), &pieces);
    eprintln!("stepper hold: {fit:?}");
    assert!(fit.worst_lit_mm <= STEPPER_TOLERANCE_MM, "{fit:?}");
    // The stretch travelled dark between `!` and rest is the one gap:
    // the hold takes the prepared segments back and brakes at once
    // (measured 0.19 mm), so it stays within about a servo resolution.
    assert!(fit.worst_missed_mm <= 0.5, "{fit:?}");
}
