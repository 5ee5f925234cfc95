//! Paths in the simulator, end to end: long paths never hold the other
//! tasks up, unreachable figures are refused or stop dark, and the laser
//! is lit only on the figure (travel to it is dark).

use laser_app::domain::{self, Actuator, AimModel, Pattern, PointCm, check_pattern, pass_points};
use laser_app::settings::Settings;
use laser_sim::recorder::{Direction, SpotSample};
use laser_sim::world::{SimOptions, SimReport};
use proptest::prelude::*;
use system_tests::{reply_to, run_with, sent_at, terminal_lines};

/// Host CPU time one executor poll may take, µs. The old pattern check
/// walked a 40 000-point path from its start for every point (8.5 s in
/// one poll here); aiming at all 40 000 points once takes ~15 ms. A poll
/// that aims at a handful of points takes well under 0.1 ms. The limit
/// leaves room for a loaded CI host (one 2 ms poll was seen with several
/// builds running) and still catches a poll that walks the whole path.
const LONGEST_POLL_US: u128 = 5_000;

/// How long a command may wait for its reply while a path runs, µs of
/// simulated time.
const REPLY_WITHIN_US: u64 = 5_000;

/// Runs `script`; the report and its longest firmware step (host CPU),
/// counting only long steps that recur in every run (see `steady_steps`).
fn run_timed(script: &str, options: SimOptions) -> (SimReport, std::time::Duration) {
    let report = system_tests::steady_steps(|| run_with(script, options.clone()));
    let longest = laser_sim::executor::longest_firmware_step(&report.task_steps);
    (report, longest)
}

#[test]
fn a_forty_thousand_point_line_starts_at_once_and_never_holds_the_executor() {
    // 400 cm at 0.01 cm: 40 000 points.
    let script = "set path.step_cm 0.01\npattern line -200 0 200 0 once\nwait 1500\nstatus\n\
                  wait 100\nstatus\nstop\nstatus\n";
    let wall = std::time::Instant::now();
    let (report, longest) = run_timed(script, SimOptions::default());
    eprintln!(
        "40k-point line: {:?} host time for the whole run, longest poll {longest:?}",
        wall.elapsed()
    );
    assert!(
        longest.as_micros() < LONGEST_POLL_US,
        "one executor poll took {longest:?}"
    );
    for line in ["pattern line -200 0 200 0 once", "status", "stop"] {
        let (latency, reply) = reply_to(&report, line);
        assert_eq!(reply, "ok", "{line}");
        assert!(
            latency < REPLY_WITHIN_US,
            "{line}: reply after {latency} µs"
        );
    }
    // The run got going: after the approach (~0.4 s) it drew points.
    let lines = terminal_lines(&report);
    let points: Vec<usize> = lines
        .iter()
        .filter_map(|l| l.strip_prefix("state: pattern line once point "))
        .filter_map(|rest| rest.split(' ').next()?.parse().ok())
        .collect();
    assert_eq!(points.len(), 2, "{lines:?}");
    assert!(points[0] > 10 && points[1] > points[0], "points {points:?}");
    assert_eq!(lines.last(), Some(&"ok"));
    assert!(lines.contains(&"state: idle"));
    assert_eq!(
        report.recording.laser_events.last().map(|e| e.1),
        Some(false)
    );
    // Lit only on the drawn start of the line, never on the way there
    // from home (along y = 0 too). Out there, 200 cm off the axis, 0.1° of
    // servo resolution is 3.5 mm on the board.
    let lit: Vec<&SpotSample> = report.recording.spot.iter().filter(|s| s.laser).collect();
    assert!(!lit.is_empty());
    for s in lit {
        assert!(
            s.y_cm.abs() < 0.5 && s.x_cm < -195.0,
            "lit at ({}, {})",
            s.x_cm,
            s.y_cm
        );
    }
}

#[test]
fn set_during_a_long_path_is_cheap_and_still_refuses_what_breaks_it() {
    let mut script = String::from("set path.step_cm 0.01\npattern line -200 0 200 0\nwait 800\n");
    for k in 0..20 {
        script.push_str(&format!("set servo.speed_deg_s {}\n", 150 + k));
    }
    // The line's ends are at yaw ±83°: refused, the run goes on.
    script.push_str("set yaw.max_deg 60\nwait 300\nstatus\nstop\n");
    let (report, longest) = run_timed(&script, SimOptions::default());
    assert!(
        longest.as_micros() < LONGEST_POLL_US,
        "one executor poll took {longest:?}"
    );
    for k in 0..20 {
        let line = format!("set servo.speed_deg_s {}", 150 + k);
        let (latency, reply) = reply_to(&report, &line);
        assert_eq!(reply, "ok", "{line}");
        assert!(
            latency < REPLY_WITHIN_US,
            "{line}: reply after {latency} µs"
        );
    }
    let (latency, reply) = reply_to(&report, "set yaw.max_deg 60");
    assert!(
        reply.starts_with("error: line passes (") && reply.contains("unreachable"),
        "{reply}"
    );
    assert!(latency < REPLY_WITHIN_US);
    let lines = terminal_lines(&report);
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("state: pattern line point ")),
        "still running: {lines:?}"
    );
}

#[test]
fn unreachable_figures_are_refused_before_anything_moves_or_lights() {
    for figure in [
        "line -10 0 40 0",
        "circle 5 0 30 cw",
        "rect -5 -5 35 5",
        // 40 000 points: refused just as fast.
        "line -200 0 200 0",
    ] {
        let script = format!(
            "set path.step_cm 0.01\nset yaw.min_deg -45\nset yaw.max_deg 45\npattern {figure} once\nwait 200\n"
        );
        let report = run_with(&script, SimOptions::default());
        let line = format!("pattern {figure} once");
        let (latency, reply) = reply_to(&report, &line);
        assert!(
            reply.starts_with("error: ") && reply.contains("unreachable"),
            "{figure}: {reply}"
        );
        assert!(latency < REPLY_WITHIN_US);
        assert!(
            report.recording.laser_events.iter().all(|(_, on)| !on),
            "{figure}: laser lit"
        );
        let moves = report
            .recording
            .frames
            .iter()
            .filter(|f| f.direction == Direction::Tx && f.bytes.get(2) == Some(&25))
            .count();
        assert_eq!(moves, 0, "{figure}: servos moved");
        assert!(report.idle_at_end);
    }
}

/// Pitch limit (servo deg) at which the check before the start passes
/// while some interpolated point of `pattern` cannot be reached: the
/// reachable region is not convex on the board (pitch limits are conics),
/// so points between the checked ones can fail.
fn limit_between_probes(pattern: &Pattern) -> (&'static str, f64) {
    let base = Settings::default();
    let points: Vec<PointCm> = pass_points(pattern, &base.aimer(AimModel::Exact))
        .expect("a path")
        .map(|t| t.point)
        .collect();
    let pitch = |s: &Settings, p: PointCm| {
        s.aimer(AimModel::Exact)
            .aim(p)
            .map(|a| f64::from(a.pitch_wire) / 10.0)
    };
    let peak = points
        .iter()
        .map(|p| pitch(&base, *p).expect("reachable by default"))
        .fold(0.0f64, |m, v| if v.abs() > m.abs() { v } else { m });
    for k in 1..200 {
        let limit = peak.abs() - 0.01 * f64::from(k);
        let mut s = base;
        let name = if peak > 0.0 {
            s.pitch.max_deg = limit;
            "pitch.max_deg"
        } else {
            s.pitch.min_deg = -limit;
            "pitch.min_deg"
        };
        let checked = check_pattern(pattern, &s.aimer(AimModel::Exact), Actuator::Gimbal);
        let some_fail = points.iter().any(|p| pitch(&s, *p).is_err());
        if checked.is_ok() && some_fail {
            return (name, if peak > 0.0 { limit } else { -limit });
        }
    }
    panic!("every pitch limit that cuts the line is found before the start");
}

#[test]
fn a_figure_unreachable_between_checked_points_stops_dark_at_the_first_bad_point() {
    let (x0, x1, y) = (-60.0, 47.0, 20.0);
    let pattern = Pattern::Path(domain::Figure::Line {
        from: PointCm { x_cm: x0, y_cm: y },
        to: PointCm { x_cm: x1, y_cm: y },
    });
    let (param, limit) = limit_between_probes(&pattern);
    let script = format!("set {param} {limit:.2}\npattern line {x0} {y} {x1} {y} once\n");
    let report = run_with(&script, SimOptions::default());
    let (_, reply) = reply_to(&report, &format!("pattern line {x0} {y} {x1} {y} once"));
    assert_eq!(reply, "ok", "passes the check before the start");
    let (t_notice, notice) = report
        .transcript
        .notices
        .iter()
        .find(|(_, n)| n.starts_with("[error: line stopped, laser off: point ("))
        .cloned()
        .unwrap_or_else(|| panic!("stop notice: {:?}", report.transcript.notices));
    assert!(notice.contains("unreachable"), "{notice}");
    // Dark no later than the notice, and for good.
    let &(t_off, on) = report.recording.laser_events.last().expect("laser used");
    assert!(
        !on && t_off <= t_notice,
        "off at {t_off}, notice at {t_notice}"
    );
    assert!(report.idle_at_end);
    // Lit only on the line, and only on its reachable part: the spot
    // never passed the first unreachable point.
    let bad_x: f64 = notice
        .trim_start_matches("[error: line stopped, laser off: point (")
        .split(',')
        .next()
        .and_then(|x| x.trim().parse().ok())
        .expect("x of the unreachable point");
    let lit: Vec<&SpotSample> = report.recording.spot.iter().filter(|s| s.laser).collect();
    assert!(!lit.is_empty());
    for s in lit {
        assert!((s.y_cm - y).abs() < 0.15, "lit at ({}, {})", s.x_cm, s.y_cm);
        assert!(s.x_cm < bad_x, "lit at x {} past {bad_x}", s.x_cm);
    }
}

/// A figure on the board, for the distance of the spot from it (cm).
#[derive(Debug, Clone, Copy)]
enum Figure {
    Line((f64, f64), (f64, f64)),
    Circle((f64, f64), f64, bool),
    Rect((f64, f64), (f64, f64)),
}

fn segment_distance(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 == 0.0 {
        0.0
    } else {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    };
    (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
}

impl Figure {
    fn command(&self) -> String {
        match *self {
            Figure::Line(a, b) => format!("line {} {} {} {}", a.0, a.1, b.0, b.1),
            Figure::Circle(c, r, ccw) => {
                format!(
                    "circle {} {} {r} {}",
                    c.0,
                    c.1,
                    if ccw { "ccw" } else { "cw" }
                )
            }
            Figure::Rect(a, b) => format!("rect {} {} {} {}", a.0, a.1, b.0, b.1),
        }
    }

    fn start(&self) -> (f64, f64) {
        match *self {
            Figure::Line(a, _) | Figure::Rect(a, _) => a,
            Figure::Circle(c, r, _) => (c.0, c.1 + r),
        }
    }

    fn distance(&self, p: (f64, f64)) -> f64 {
        match *self {
            Figure::Line(a, b) => segment_distance(p, a, b),
            Figure::Circle(c, r, _) => ((p.0 - c.0).hypot(p.1 - c.1) - r).abs(),
            Figure::Rect(a, b) => {
                let corners = [a, (b.0, a.1), b, (a.0, b.1)];
                (0..4)
                    .map(|k| segment_distance(p, corners[k], corners[(k + 1) % 4]))
                    .fold(f64::INFINITY, f64::min)
            }
        }
    }
}

/// Length of the lit spot path farther than `tolerance_cm` from `figure`
/// after `from_us`, cm (consecutive lit samples).
fn stray_lit_cm(report: &SimReport, figure: &Figure, from_us: u64, tolerance_cm: f64) -> f64 {
    let samples: Vec<&SpotSample> = report
        .recording
        .spot
        .iter()
        .filter(|s| s.t_us >= from_us)
        .collect();
    samples
        .windows(2)
        .filter(|w| w[0].laser && w[1].laser)
        .filter(|w| {
            figure.distance((w[0].x_cm, w[0].y_cm)) > tolerance_cm
                || figure.distance((w[1].x_cm, w[1].y_cm)) > tolerance_cm
        })
        .map(|w| (w[1].x_cm - w[0].x_cm).hypot(w[1].y_cm - w[0].y_cm))
        .sum()
}

#[test]
fn the_reported_approach_from_home_is_dark() {
    // Issue 9, defect 11: from home, the approach to (-9.3, -5.1) was lit.
    let figure = Figure::Line((-9.3, -5.1), (8.7, 6.2));
    let report = run_with(
        &format!("pattern {} once\n", figure.command()),
        SimOptions::default(),
    );
    assert!(report.succeeded(false), "{:?}", report.transcript);
    let stray = stray_lit_cm(&report, &figure, 0, 0.15);
    eprintln!("stray lit path from home: {:.1} mm", stray * 10.0);
    assert!(stray < 0.05, "{:.1} mm lit off the line", stray * 10.0);
    assert!(report.recording.spot.iter().any(|s| s.laser));
}

#[test]
fn passes_of_a_closed_figure_stay_lit_and_the_way_back_to_an_open_one_is_dark() {
    // A circle's passes start where the last one ended: no travel, lit
    // throughout. A line's next pass starts back at its start: dark.
    let circle = run_with(
        "pattern circle 1 1 1.5 ccw\nwait 6000\nstatus\nstop\n",
        SimOptions::default(),
    );
    let stop = sent_at(&circle, "stop");
    let events = &circle.recording.laser_events;
    let first_on = events
        .iter()
        .position(|(_, on)| *on)
        .expect("the circle was lit");
    let later: Vec<_> = events[first_on + 1..]
        .iter()
        .filter(|(t, _)| *t < stop)
        .collect();
    assert!(later.is_empty(), "dark between passes: {later:?}");
    let lines = terminal_lines(&circle);
    let pass: u32 = lines
        .iter()
        .find_map(|l| l.strip_prefix("state: pattern circle point "))
        .and_then(|rest| rest.split(" pass ").nth(1)?.parse().ok())
        .unwrap_or_else(|| panic!("{lines:?}"));
    assert!(pass >= 2, "{pass} passes");
    let figure = Figure::Line((-3.0, -1.0), (2.0, 2.0));
    let line = run_with(
        &format!("pattern {}\nwait 6000\nstop\n", figure.command()),
        SimOptions::default(),
    );
    let ons = line
        .recording
        .laser_events
        .iter()
        .filter(|(_, on)| *on)
        .count();
    assert!(
        ons >= 2,
        "dark between passes: {:?}",
        line.recording.laser_events
    );
    assert!(stray_lit_cm(&line, &figure, 0, ON_FIGURE_CM) < 0.05);
}

/// How far from the figure a lit spot may be, cm. Half a step of
/// interpolation, joint-space chords between points and the servos' 0.1°
/// resolution give 1.5 mm on smooth figures; at a corner the next point
/// goes out once the servos are within their 0.5° arrival deadband of the
/// corner (~2.5 mm on the board), so the spot may cut it by that much.
/// Travel to the figure from elsewhere on the board would be centimetres.
const ON_FIGURE_CM: f64 = 0.3;

fn figure_strategy() -> impl Strategy<Value = Figure> {
    let point = (-12.0f64..12.0, -8.0f64..8.0);
    let round = |v: f64| (v * 100.0).round() / 100.0;
    let rp = move |(x, y): (f64, f64)| (round(x), round(y));
    prop_oneof![
        // Figures the command line accepts: a line at least 0.1 cm long,
        // rect sides at least 0.1 cm.
        (point.clone(), point.clone())
            .prop_map(move |(a, b)| (rp(a), rp(b)))
            .prop_filter("a line at least 0.1 cm long", |(a, b)| {
                (b.0 - a.0).abs().max((b.1 - a.1).abs()) >= 0.1
            })
            .prop_map(|(a, b)| Figure::Line(a, b)),
        ((-6.0f64..6.0, -4.0f64..4.0), 0.5f64..4.0, any::<bool>())
            .prop_map(move |(c, r, ccw)| Figure::Circle(rp(c), round(r), ccw)),
        (
            point.clone(),
            (0.2f64..6.0, 0.2f64..4.0),
            any::<(bool, bool)>()
        )
            .prop_map(move |(a, (w, h), (left, down))| {
                let d = (if left { -w } else { w }, if down { -h } else { h });
                Figure::Rect(rp(a), rp((a.0 + d.0, a.1 + d.1)))
            }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 48,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn the_spot_is_lit_only_on_the_figure_and_the_approach_is_dark(
        figure in figure_strategy(),
        from in (-14.0f64..14.0, -9.0f64..9.0),
        mode in prop_oneof![Just("auto"), Just("dwell")],
    ) {
        let from = ((from.0 * 100.0f64).round() / 100.0, (from.1 * 100.0f64).round() / 100.0);
        let pattern = format!("pattern {} once", figure.command());
        let script = format!(
            "set dwell_ms 0\ngoto {} {}\nwait 400\nlaser {mode}\n{pattern}\n",
            from.0, from.1
        );
        let report = run_with(&script, SimOptions::default());
        prop_assert!(report.succeeded(false), "{:?}", report.transcript);
        let started = sent_at(&report, &pattern);
        // Dark from the start of the pattern until the spot reached the
        // figure's start.
        let off = report
            .recording
            .laser_events
            .iter()
            .find(|(t, _)| *t >= started)
            .copied();
        prop_assert!(matches!(off, Some((_, false))), "dark at the start: {:?}", off);
        let lit: Vec<&SpotSample> = report
            .recording
            .spot
            .iter()
            .filter(|s| s.t_us > started && s.laser)
            .collect();
        for s in &lit {
            let d = figure.distance((s.x_cm, s.y_cm));
            prop_assert!(
                d <= ON_FIGURE_CM,
                "lit ({:.3}, {:.3}) is {:.2} mm off {:?}", s.x_cm, s.y_cm, d * 10.0, figure
            );
        }
        let drawn = match figure {
            Figure::Line(a, b) | Figure::Rect(a, b) => (a.0 - b.0).hypot(a.1 - b.1) > 1.0,
            Figure::Circle(..) => true,
        };
        prop_assert!(mode == "dwell" || !drawn || !lit.is_empty(), "auto drew nothing");
        if let Some(first) = lit.first() {
            let start = figure.start();
            let d = (first.x_cm - start.0).hypot(first.y_cm - start.1);
            prop_assert!(d <= 0.35, "first lit {:.2} mm from the start", d * 10.0);
        }
        prop_assert_eq!(report.recording.laser_events.last().map(|e| e.1), Some(false));
    }
}

/// Galvo spot of a DAC sample, mm.
fn galvo_spot_mm(s: &laser_app::galvo::DacSample) -> (f64, f64) {
    let p = kinematics_core::Galvo::<f64>::default()
        .codes_to_board(s.x_code, s.y_code)
        .expect("codes in range");
    (p.x_mm, p.y_mm)
}

#[test]
fn galvo_travel_between_figures_strokes_and_passes_is_dark() {
    // A goto, the tuning figure (four strokes) repeated, then a line
    // repeated: every lit stretch starts on a stroke's start and, unless a
    // command cut it, ends on that stroke's end.
    let report = run_with(
        "target galvo\ngoto 8 6\nwait 30\npattern tuning 1 -1 5\nwait 1600\n\
         pattern line -3 -2 4 3\nwait 400\nstop\nwait 10\n",
        SimOptions::default(),
    );
    assert!(report.succeeded(false), "{:?}", report.transcript);
    let near = |p: (f64, f64), q: (f64, f64)| (p.0 - q.0).hypot(p.1 - q.1) < 0.15;
    // (figure, stroke start, stroke end), mm: centre (10, −10), half side 25.
    let strokes = [
        ("goto", (80.0, 60.0), (80.0, 60.0)),
        ("tuning", (-15.0, 15.0), (-15.0, 15.0)),
        ("tuning", (10.0, 15.0), (10.0, 15.0)),
        ("tuning", (-15.0, -10.0), (35.0, -10.0)),
        ("tuning", (10.0, 15.0), (10.0, -35.0)),
        ("line", (-30.0, -20.0), (40.0, 30.0)),
    ];
    let samples: Vec<_> = report.dac.iter().map(|(_, s)| s).collect();
    // (figure, first lit spot, last lit spot), mm.
    type LitStretch<'a> = (&'a str, (f64, f64), (f64, f64));
    let mut runs: Vec<LitStretch> = Vec::new();
    let mut k = 0;
    while k < samples.len() {
        if !samples[k].laser {
            k += 1;
            continue;
        }
        let first = galvo_spot_mm(&samples[k]);
        while k < samples.len() && samples[k].laser {
            k += 1;
        }
        let last = galvo_spot_mm(&samples[k - 1]);
        let figure = strokes
            .iter()
            .find(|(_, start, _)| near(first, *start))
            .map(|(f, _, _)| *f)
            .unwrap_or_else(|| panic!("a lit stretch starts at {first:?}, no stroke's start"));
        runs.push((figure, first, last));
    }
    let count = |name: &str| runs.iter().filter(|r| r.0 == name).count();
    assert_eq!(count("goto"), 1);
    assert!(count("tuning") >= 8, "two passes of four strokes: {runs:?}");
    assert!(count("line") >= 2, "two passes of the line: {runs:?}");
    for (i, (figure, first, last)) in runs.iter().enumerate() {
        let cut_by_a_command = runs.get(i + 1).is_none_or(|next| next.0 != *figure);
        let ends_a_stroke = strokes
            .iter()
            .any(|(f, start, end)| f == figure && near(*first, *start) && near(*last, *end));
        assert!(
            cut_by_a_command || ends_a_stroke,
            "{figure} lit from {first:?} to {last:?}: not one stroke"
        );
    }
}
