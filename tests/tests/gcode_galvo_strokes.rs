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

/// How often the lit samples cover each point of a polyline toolpath.
#[derive(Debug)]
struct Exposure {
    /// Toolpath length, mm.
    toolpath_mm: f64,
    /// Toolpath length lit by two or more laser-on intervals, mm.
    twice_mm: f64,
    /// Toolpath length no lit sample covers, mm.
    unmarked_mm: f64,
}

/// Bins of the toolpath the exposure is counted in, mm.
const BIN_MM: f64 = 0.01;
/// Lit samples of one interval closer than this along the toolpath
/// cover it between them, mm: the DAC's 12-bit codes step the spot by
/// up to 0.15 mm on the board.
const MERGE_MM: f64 = 0.3;

/// Projects the lit samples of each laser-on interval onto the polyline
/// `points` (arc length, mm) and counts, per 0.01 mm of it, the intervals
/// that cover it (consecutive samples closer than [`MERGE_MM`] along it).
fn exposure(report: &SimReport, points: &[[f64; 2]]) -> Exposure {
    let lengths: Vec<f64> = points
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .collect();
    let total: f64 = lengths.iter().sum();
    let along = |p: [f64; 2]| {
        let (mut best, mut s_best, mut s0) = (f64::MAX, 0.0, 0.0);
        for (w, len) in points.windows(2).zip(&lengths) {
            let d = [w[1][0] - w[0][0], w[1][1] - w[0][1]];
            let t =
                (((p[0] - w[0][0]) * d[0] + (p[1] - w[0][1]) * d[1]) / (len * len)).clamp(0.0, 1.0);
            let q = [w[0][0] + d[0] * t, w[0][1] + d[1] * t];
            let dist = (p[0] - q[0]).hypot(p[1] - q[1]);
            if dist < best {
                (best, s_best) = (dist, s0 + t * len);
            }
            s0 += len;
        }
        s_best
    };
    let bins = (total / BIN_MM).ceil() as usize + 1;
    let mut count = vec![0u32; bins];
    let mut interval: Vec<f64> = Vec::new();
    let mut flush = |interval: &mut Vec<f64>| {
        interval.sort_by(f64::total_cmp);
        let mut covered = vec![false; bins];
        for w in interval.windows(2).filter(|w| w[1] - w[0] < MERGE_MM) {
            let (a, b) = ((w[0] / BIN_MM) as usize, (w[1] / BIN_MM) as usize);
            covered[a.min(bins - 1)..=b.min(bins - 1)].fill(true);
        }
        for (c, hit) in count.iter_mut().zip(covered) {
            *c += u32::from(hit);
        }
        interval.clear();
    };
    for (_, p, lit) in galvo_spot_mm(report) {
        if lit {
            interval.push(along(p));
        } else if !interval.is_empty() {
            flush(&mut interval);
        }
    }
    flush(&mut interval);
    let span = |n: usize| n as f64 * BIN_MM;
    Exposure {
        toolpath_mm: total,
        twice_mm: span(count.iter().filter(|&&c| c >= 2).count()),
        unmarked_mm: span(count.iter().filter(|&&c| c == 0).count()),
    }
}

/// Holds `points` drawn as G1s at the `n`-th G1 after `wait_ms`, asks
/// `?` while stopping and once held, resumes 500 ms later; checks the
/// hold (dark within 1 ms, nothing lit until `~`, `Hold:1` then `Hold:0`)
/// and the drawn path (`MPos` once held on it), and returns the exposure
/// and that of the same job without the hold.
fn hold_and_resume(
    label: &str,
    points: &[[f64; 2]],
    at: &dyn Fn(&Job) -> usize,
    wait_ms: u32,
) -> (Exposure, Exposure) {
    let job = job_of(points);
    let at = at(&job);
    let wait = format!("wait {wait_ms}");
    let report = run_galvo(
        &job,
        &[
            (at, &wait),
            (at, "!"),
            (at, "?"),
            (at, "wait 500"),
            (at, "?"),
            (at, "~"),
        ],
    );
    let lit_in_hold = system_tests::lit_between_ns(&report, "!", "~");
    assert!(lit_in_hold.is_empty(), "{label}: lit in the hold");
    let status: Vec<&str> = terminal_lines(&report)
        .into_iter()
        .filter(|l| l.starts_with("<Hold"))
        .collect();
    assert!(status.len() == 2, "{label}: {status:?}");
    assert!(status[0].starts_with("<Hold:1"), "{label}: {status:?}");
    assert!(status[1].starts_with("<Hold:0"), "{label}: {status:?}");
    // Marked up to the hold, then from where it stopped.
    assert_eq!(laser_on_times_ns(&report).len(), 2, "{label}");
    assert_on_toolpath(&report, &job);
    let mpos: Vec<f64> = status[1]
        .split(['|', ','])
        .skip(1)
        .take(2)
        .map(|v| v.trim_start_matches("MPos:").parse().expect("MPos"))
        .collect();
    let off = job.pieces.iter().map(|p| p.distance([mpos[0], mpos[1]]));
    let off = off.fold(f64::MAX, f64::min);
    assert!(
        off <= GALVO_TOLERANCE_MM,
        "{label}: held {off} mm off the path"
    );
    let held = exposure(&report, points);
    let plain = exposure(&run_galvo(&job, &[]), points);
    eprintln!(
        "{label}: held {held:?}, without the hold {plain:?}; {}",
        status[1]
    );
    (held, plain)
}

/// Nothing marked twice (within one 1.28 ms half buffer of marking,
/// 0.03 mm at 20 mm/s), nothing more left unmarked than without the hold.
fn assert_marked_once(held: &Exposure, plain: &Exposure) {
    assert!(held.twice_mm <= 0.05, "{held:?}");
    assert!(
        held.unmarked_mm <= plain.unmarked_mm + 0.05,
        "{held:?} {plain:?}"
    );
    assert!(held.unmarked_mm < 0.01 * held.toolpath_mm, "{held:?}");
}

#[test]
fn a_hold_mid_line_resumes_where_marking_stopped_on_the_square() {
    // All four G1s sent; 1.5 s into the square's 4 s contour: on its
    // second G1.
    let at = |job: &Job| nth_line(job, "M5", 1);
    let (held, plain) = hold_and_resume("square", &square(), &at, 1500);
    // Before, the stroke was marked again from its start: 29.9 mm twice.
    assert_marked_once(&held, &plain);
}

#[test]
fn a_hold_mid_contour_resumes_where_marking_stopped_on_the_circle() {
    // 16 G1s queued (the queue's size) when it holds, 0.7 s into the
    // 3.1 s contour; the rest follow the resume.
    let at = |job: &Job| nth_line(job, "G1", 17);
    let (held, plain) = hold_and_resume("circle", &circle_of_chords(), &at, 700);
    // Before, the piece in flight was marked again: 3.5 mm twice.
    assert_marked_once(&held, &plain);
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
