//! Consecutive lit G-code blocks on the galvo are marked as one stroke
//! per contour, however many blocks it has (issue 12's galvo look-ahead;
//! the sequencer sends the contour in pieces that the galvo loop joins
//! while it marks): one jump and one pair of laser delays per contour,
//! corners at the path planner's junction speed, and the drawn path
//! still on the toolpath. Hold and reset mid-contour darken at once; a
//! sender that pauses mid-contour ends the stroke dark.

use laser_sim::world::{SimOptions, SimReport};
use system_tests::gcode_job::{Job, fit, rapids_dark};
use system_tests::gcode_toolpath::{galvo_spot_mm, lit_mm};
use system_tests::{UNTIL_STEP_FIXES, assert_safe_allowing, run_with, terminal_lines};

/// Board positions (mm) of the galvo's lit DAC samples.
fn galvo_lit_mm(report: &SimReport) -> Vec<[f64; 2]> {
    lit_mm(&galvo_spot_mm(report))
}

/// The galvo's tolerance (issue 12).
const GALVO_TOLERANCE_MM: f64 = 0.2;

/// A galvo job drawing `points` as lit G1s at F1200, then a G0 home.
fn job_of(points: &[[f64; 2]]) -> Job {
    let mut job = Job::default();
    job.line("G21 G90");
    job.line("M3");
    job.polyline(points, 1200.0, 1000.0);
    job.line("M5");
    job.rapid([0.0, 0.0]);
    job.line("M2");
    job
}

fn square() -> Vec<[f64; 2]> {
    vec![
        [-10.0, -10.0],
        [10.0, -10.0],
        [10.0, 10.0],
        [-10.0, 10.0],
        [-10.0, -10.0],
    ]
}

/// A circle of radius 10 mm as 36 G1 chords.
fn circle_of_chords() -> Vec<[f64; 2]> {
    (0..=36)
        .map(|k| {
            let a = core::f64::consts::TAU * f64::from(k) / 36.0;
            [10.0 * a.cos(), 10.0 * a.sin()]
        })
        .collect()
}

fn run_galvo(job: &Job, extra: &[(usize, &str)]) -> SimReport {
    let mut lines = job.lines.clone();
    for &(at, line) in extra.iter().rev() {
        lines.insert(at, line.into());
    }
    let mut text = String::from("target galvo\n");
    for l in &lines {
        text.push_str(l);
        text.push('\n');
    }
    let report = run_with(&text, SimOptions::default());
    let errors: Vec<String> = terminal_lines(&report)
        .into_iter()
        .filter(|l| l.starts_with("error") || l.starts_with("ALARM"))
        .map(String::from)
        .collect();
    assert!(errors.is_empty(), "{errors:?}");
    assert!(report.idle_at_end, "still running at the end");
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    report
}

/// The lit samples lie on `job`'s toolpath (within the galvo's
/// tolerance) and cover it (gaps within 0.5 mm).
fn assert_on_toolpath(report: &SimReport, job: &Job) {
    let fit = fit(&galvo_lit_mm(report), &job.pieces);
    assert!(fit.worst_lit_mm <= GALVO_TOLERANCE_MM, "{fit:?}");
    assert!(fit.worst_missed_mm <= 0.5, "{fit:?}");
}

/// Times (ns) the galvo laser turned on.
fn laser_on_times_ns(report: &SimReport) -> Vec<u64> {
    let mut lit = false;
    let mut ons = Vec::new();
    for (t, s) in report.dac.iter() {
        if s.laser && !lit {
            ons.push(t);
        }
        lit = s.laser;
    }
    ons
}

/// Draws `points`: returns its strokes (laser on-transitions) and job
/// time (s), after checking the lit path and the dark G0s.
fn draw(label: &str, points: &[[f64; 2]]) -> (usize, f64) {
    draw_job(label, &job_of(points))
}

/// Draws `job` on the galvo: returns its strokes (laser on-transitions)
/// and job time (s), after checking the lit path and the dark G0s.
fn draw_job(label: &str, job: &Job) -> (usize, f64) {
    let report = run_galvo(job, &[]);
    let (lit, timeline) = (galvo_lit_mm(&report), galvo_spot_mm(&report));
    let fit = fit(&lit, &job.pieces);
    assert!(fit.worst_lit_mm <= GALVO_TOLERANCE_MM, "{label}: {fit:?}");
    assert!(fit.worst_missed_mm <= 0.5, "{label}: {fit:?}");
    let spans = rapids_dark(&timeline, &job.rapids, GALVO_TOLERANCE_MM)
        .unwrap_or_else(|e| panic!("{label}: {e}"));
    assert_eq!(spans.len(), job.rapids.len(), "{label}: {spans:?}");
    assert!(
        spans.iter().all(|s| s.lit == 0),
        "{label}: lit G0 {spans:?}"
    );
    let strokes = laser_on_times_ns(&report).len();
    let seconds = report.end_time_us as f64 / 1e6;
    eprintln!(
        "{label}: {} lit pieces, {strokes} strokes, worst off path {:.3} mm, gap {:.3} mm, job {seconds:.3} s",
        job.pieces.len(),
        fit.worst_lit_mm,
        fit.worst_missed_mm,
    );
    (strokes, seconds)
}

#[test]
fn a_square_of_four_g1s_is_one_stroke_on_the_toolpath() {
    let (strokes, _) = draw("square", &square());
    assert_eq!(strokes, 1);
}

#[test]
fn a_circle_of_36_g1s_is_one_stroke() {
    let (strokes, seconds) = draw("circle", &circle_of_chords());
    // One laser on/off pair (9 strokes of four lines before, 36 before
    // that).
    assert_eq!(strokes, 1);
    // The 2π·10 mm path at 20 mm/s alone takes 3.13 s; 3.188 s with a
    // stroke every four lines, 3.326 s with one per G1.
    assert!(seconds < 3.17, "{seconds} s");
}

#[test]
fn a_hold_mid_stroke_is_dark_and_resume_completes_the_square() {
    let job = job_of(&square());
    // The square's first G1 is line 4 (after G21, M3, G0); hold 1.5 s
    // into its 4 s stroke, resume 0.5 s later.
    let at = job.lines.len() - 3;
    let report = run_galvo(
        &job,
        &[(at, "wait 1500"), (at, "!"), (at, "wait 500"), (at, "~")],
    );
    let hold_us = system_tests::sent_at(&report, "!");
    let resume_us = system_tests::sent_at(&report, "~");
    let ons = laser_on_times_ns(&report);
    let lit_in_hold = system_tests::lit_between_ns(&report, "!", "~");
    assert!(
        lit_in_hold.is_empty(),
        "{} lit samples in the hold {hold_us}..{resume_us} µs, from {:?} ns; on at {ons:?}",
        lit_in_hold.len(),
        lit_in_hold.first()
    );
    // Marked before the hold, then again from the stroke's start.
    assert_eq!(ons.len(), 2, "{ons:?}");
    assert!(ons[0] < hold_us * 1_000 && ons[1] > resume_us * 1_000);
    assert_on_toolpath(&report, &job);
}

/// Index of the `n`-th (from 1) line of `job` starting with `prefix`.
fn nth_line(job: &Job, prefix: &str, n: usize) -> usize {
    job.lines
        .iter()
        .enumerate()
        .filter(|(_, l)| l.starts_with(prefix))
        .nth(n - 1)
        .map(|(i, _)| i)
        .expect("line")
}

#[test]
fn a_hold_mid_contour_is_dark_within_a_millisecond_and_resume_completes_it() {
    let job = job_of(&circle_of_chords());
    // The sender has 16 G1s queued (the queue's size) when it holds,
    // 0.7 s into the 3.1 s contour; the rest follow the resume.
    let at = nth_line(&job, "G1", 17);
    let report = run_galvo(
        &job,
        &[(at, "wait 700"), (at, "!"), (at, "wait 500"), (at, "~")],
    );
    let lit_in_hold = system_tests::lit_between_ns(&report, "!", "~");
    assert!(lit_in_hold.is_empty(), "lit in the hold: {lit_in_hold:?}");
    let ons = laser_on_times_ns(&report);
    // Marked up to the hold, then from the step in flight again.
    assert_eq!(ons.len(), 2, "{ons:?}");
    assert_on_toolpath(&report, &job);
}

#[test]
fn a_soft_reset_mid_contour_is_dark_within_a_millisecond() {
    let job = job_of(&circle_of_chords());
    let mut text = String::from("target galvo\n");
    let at = nth_line(&job, "G1", 17);
    for (i, l) in job.lines.iter().enumerate() {
        if i == at {
            text.push_str("wait 700\n\u{18}\n");
        }
        text.push_str(l);
        text.push('\n');
    }
    let report = run_with(&text, SimOptions::default());
    let lines = terminal_lines(&report);
    assert!(lines.contains(&"ALARM:3"), "{lines:?}");
    let reset_us = system_tests::sent_at(&report, "\u{18}");
    let lit_at = system_tests::lit_sample_times_ns(&report);
    assert!(
        lit_at.iter().any(|&t| t < reset_us * 1_000),
        "marking before the reset"
    );
    let late: Vec<u64> = lit_at
        .into_iter()
        .filter(|&t| t > (reset_us + 1_000) * 1_000)
        .collect();
    assert!(late.is_empty(), "lit after the reset: {:?}", late.first());
}

#[test]
fn a_sender_pausing_mid_contour_ends_the_stroke_dark_and_goes_on() {
    let job = job_of(&circle_of_chords());
    // The sender stops after the 18th G1 for 2 s: the queue runs dry
    // (18 blocks take 1.6 s).
    let at = nth_line(&job, "G1", 19);
    let resumed = job.lines[at].clone();
    let report = run_galvo(&job, &[(at, "wait 2000")]);
    let ons = laser_on_times_ns(&report);
    // The stroke ended (dark) at the last block queued, then a new one
    // started once the sender went on.
    assert_eq!(ons.len(), 2, "{ons:?}");
    let resumed_us = system_tests::sent_at(&report, &resumed);
    assert!(ons[1] > resumed_us * 1_000, "{ons:?} vs {resumed_us} µs");
    let dark_before = report
        .dac
        .iter()
        .filter(|(t, _)| *t > ons[0] && *t < ons[1])
        .any(|(_, s)| !s.laser);
    assert!(dark_before, "dark between the two strokes");
    assert_on_toolpath(&report, &job);
}

#[test]
fn the_laser_job_marks_each_contour_as_one_stroke() {
    // One stroke per contour: the frame (4 G1s), the "L" outline (6),
    // the "A" outline (8) and its counter (3), the three circles (r 6.25
    // and 3.75 mm as two G2 halves, r 5 mm as one full G3, each arc as
    // its chords within $12), and the raster's 30 dashes (separated by S0
    // moves).
    let job = system_tests::gcode_job::laser_job(25.0);
    let (strokes, _) = draw_job("laser job", &job);
    assert_eq!(strokes, 1 + 1 + 1 + 1 + 3 + 30);
}

#[test]
fn the_svg2gcode_job_marks_each_contour_as_one_stroke() {
    // The senders' CAM job (svg2gcode 3.3.7): 37 contours, each after
    // its own G0 (frame, three circles, three glyph contours, 30
    // dashes), 387 lit G1s; sent as a plain script (no sender).
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/senders/job/job-galvo.nc");
    let text = std::fs::read_to_string(path).expect("the job file");
    let mut job = Job::from_gcode(&text).expect("the job's toolpath");
    job.lines
        .retain(|l| !l.trim().is_empty() && !l.trim_start().starts_with(';'));
    let (strokes, _) = draw_job("svg2gcode job", &job);
    assert_eq!(job.rapids.len(), 37);
    assert_eq!(strokes, job.rapids.len(), "one stroke per contour");
}
