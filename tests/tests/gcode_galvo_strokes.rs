//! Consecutive lit G-code blocks on the galvo are marked as joined
//! strokes (issue 12's galvo look-ahead): one jump and one pair of laser
//! delays per stroke, corners at the path planner's junction speed, and
//! the drawn path still on the toolpath.

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
/// Lines one galvo stroke joins (`StrokeCm::MAX_SEGMENTS`).
const STROKE_SEGMENTS: usize = laser_app::domain::StrokeCm::MAX_SEGMENTS;

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
    let job = job_of(points);
    let report = run_galvo(&job, &[]);
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
        "{label}: {} G1s, {strokes} strokes, worst off path {:.3} mm, job {seconds:.3} s",
        points.len() - 1,
        fit.worst_lit_mm
    );
    (strokes, seconds)
}

#[test]
fn a_square_of_four_g1s_is_one_stroke_on_the_toolpath() {
    let (strokes, _) = draw("square", &square());
    assert_eq!(strokes, 1);
}

#[test]
fn a_circle_of_36_g1s_is_marked_in_strokes_of_the_polyline_capacity() {
    let (strokes, seconds) = draw("circle", &circle_of_chords());
    // 36 lines, STROKE_SEGMENTS per stroke (one stroke per G1 before).
    assert_eq!(strokes, 36usize.div_ceil(STROKE_SEGMENTS));
    // The 2π·10 mm path at 20 mm/s alone takes 3.13 s; 36 separate
    // strokes added a jump and both laser delays (≈ 1.3 ms) and a stop
    // at every corner.
    assert!(seconds < 3.6, "{seconds} s");
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
    let lit = galvo_lit_mm(&report);
    let fit = fit(&lit, &job.pieces);
    assert!(fit.worst_lit_mm <= GALVO_TOLERANCE_MM, "{fit:?}");
    assert!(fit.worst_missed_mm <= 0.5, "{fit:?}");
}

/// Strokes of an arc block alone: its chords within grbl's default `$12`,
/// `STROKE_SEGMENTS` a stroke.
fn arc_strokes(from: [f64; 2], to: [f64; 2], centre: [f64; 2], clockwise: bool) -> usize {
    use laser_app::grbl::block::{Arc, PointMm};
    let tolerance = laser_app::grbl::settings_map::find(12)
        .expect("$12")
        .default;
    let p = |[x_mm, y_mm]: [f64; 2]| PointMm { x_mm, y_mm };
    let arc = Arc::new(p(from), p(to), p(centre), clockwise);
    (arc.segment_count(tolerance, 100_000) as usize).div_ceil(STROKE_SEGMENTS)
}

#[test]
fn the_laser_job_marks_runs_of_lines_as_strokes() {
    // Frame (4 G1s): 1 stroke; the "L" outline (6 G1s) and the "A"
    // outline (8 G1s): 2 strokes each, its counter (3 G1s): 1; the
    // raster's 30 dashes, separated by S0 moves: 30. Circles: each arc
    // block's chords, 4 a stroke (circles r 6.25 and 3.75 mm as two G2
    // halves, r 5 mm as one full G3).
    let job = system_tests::gcode_job::laser_job(25.0);
    let half_arcs = |c: [f64; 2], r: f64| {
        let (right, left) = ([c[0] + r, c[1]], [c[0] - r, c[1]]);
        arc_strokes(right, left, c, true) + arc_strokes(left, right, c, true)
    };
    let circles = half_arcs([-15.0, 8.75], 6.25)
        + arc_strokes([5.0, 8.75], [5.0, 8.75], [0.0, 8.75], false)
        + half_arcs([15.0, 8.75], 3.75);
    let report = run_galvo(&job, &[]);
    let (lit, timeline) = (galvo_lit_mm(&report), galvo_spot_mm(&report));
    let fit = fit(&lit, &job.pieces);
    let strokes = laser_on_times_ns(&report).len();
    eprintln!(
        "laser job: {strokes} strokes ({circles} on the circles), worst off path {:.3} mm, gap {:.3} mm, job {:.3} s",
        fit.worst_lit_mm,
        fit.worst_missed_mm,
        report.end_time_us as f64 / 1e6
    );
    assert_eq!(strokes, 1 + 2 + 2 + 1 + 30 + circles);
    assert!(fit.worst_lit_mm <= GALVO_TOLERANCE_MM, "{fit:?}");
    assert!(fit.worst_missed_mm <= 0.5, "{fit:?}");
    let spans = rapids_dark(&timeline, &job.rapids, GALVO_TOLERANCE_MM).expect("G0s found");
    assert!(spans.iter().all(|s| s.lit == 0), "lit G0 {spans:?}");
}
