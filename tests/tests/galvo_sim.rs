//! The galvo in the simulator, end to end: command line → sequencer →
//! galvo loop → simulated DAC, spot from the DAC codes through the exact
//! two-mirror kinematics.

use galvo_planner::{JumpSync, Method, RigidParams, XyStepper, plan_xy_jump};
use kinematics_core::{Galvo, PointMm};
use laser_app::galvo::DacSample;
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{
    UNTIL_GALVO_GATE, UNTIL_STEP_FIXES, UNTIL_TRAVEL_FIX, assert_safe_allowing, run_to_idle,
    run_with, spec_patterns, terminal_lines,
};

/// SPEC grid pitch, mm.
const PITCH_MM: f64 = 19.16;

fn spot_mm(s: &DacSample) -> (f64, f64) {
    let p = Galvo::<f64>::default()
        .codes_to_board(s.x_code, s.y_code)
        .expect("codes in range");
    (p.x_mm, p.y_mm)
}

fn samples(report: &SimReport) -> Vec<DacSample> {
    report.dac.iter().map(|(_, s)| s).collect()
}

/// Runs of lit samples: (first index, length, spot of the first sample).
fn lit_runs(samples: &[DacSample]) -> Vec<(usize, usize, (f64, f64))> {
    let mut runs = Vec::new();
    let mut k = 0;
    while k < samples.len() {
        if samples[k].laser {
            let start = k;
            while k < samples.len() && samples[k].laser {
                k += 1;
            }
            runs.push((start, k - start, spot_mm(&samples[start])));
        } else {
            k += 1;
        }
    }
    runs
}

fn check_galvo_pattern(name: &str, expected: Vec<(i8, i8)>) {
    // Each point takes ~21 ms; the DAC outputs what the loop computed up
    // to two half buffers after the loop reported the last point done.
    let wait_ms = expected.len() * 25 + 10;
    let report = run_to_idle(&format!(
        "target galvo\nset dwell_ms 20\npattern {name} once\nwait {wait_ms}\n"
    ));
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    assert!(report.succeeded(false), "{name}: {:?}", report.transcript);
    assert_eq!(report.galvo_underruns, 0);
    let samples = samples(&report);
    let runs = lit_runs(&samples);
    assert_eq!(
        runs.len(),
        expected.len(),
        "{name}: one lit dwell per point"
    );
    for ((start, len, _), (xi, yi)) in runs.iter().zip(&expected) {
        let want = (f64::from(*xi) * PITCH_MM, f64::from(*yi) * PITCH_MM);
        assert_eq!(*len, 2000, "{name}: 20 ms dwell at 100 kHz");
        for s in &samples[*start..start + len] {
            let p = spot_mm(s);
            assert!(
                (p.0 - want.0).abs() <= 0.1 && (p.1 - want.1).abs() <= 0.1,
                "{name}: grid ({xi}, {yi}) lit at ({:.3}, {:.3}) mm",
                p.0,
                p.1
            );
        }
        // Laser delays: 100 µs dark and still before and after.
        let (before, after) = (
            &samples[start - 10..*start],
            &samples[start + len..start + len + 10],
        );
        for s in before.iter().chain(after) {
            assert!(
                !s.laser
                    && (s.x_code, s.y_code) == (samples[*start].x_code, samples[*start].y_code)
            );
        }
    }
    // Laser off whenever the mirrors move.
    for w in samples.windows(2) {
        if (w[0].x_code, w[0].y_code) != (w[1].x_code, w[1].y_code) {
            assert!(!w[0].laser && !w[1].laser, "{name}: lit while moving");
        }
    }
    // The gimbal's laser stayed off.
    assert!(report.recording.laser_events.iter().all(|(_, on)| !on));
}

#[test]
fn every_grid_pattern_runs_on_the_galvo() {
    check_galvo_pattern("corner", spec_patterns::corner());
    check_galvo_pattern("horizontal", spec_patterns::horizontal());
    check_galvo_pattern("vertical", spec_patterns::vertical());
    check_galvo_pattern("visit-all", spec_patterns::visit_all());
    check_galvo_pattern("grid-full serpentine", spec_patterns::serpentine());
    check_galvo_pattern("grid-full raster", spec_patterns::raster());
    check_galvo_pattern("home", vec![(0, 0)]);
}

/// Samples of a planned rest-to-rest jump and its largest per-sample DAC
/// step, straight from the planner.
fn planned_jump(from_mm: (f64, f64), to_mm: (f64, f64), method: Method) -> (usize, u16) {
    let galvo = Galvo::<f64>::default();
    let disc = RigidParams::REFERENCE
        .model()
        .and_then(|m| m.discretize(10e-6))
        .expect("reference drive");
    let angles = |(x_mm, y_mm)| {
        let a = galvo
            .geometry
            .ik(PointMm { x_mm, y_mm })
            .expect("reachable");
        [a.x_rad, a.y_rad]
    };
    let jump = plan_xy_jump(
        &disc,
        &disc,
        angles(from_mm),
        angles(to_mm),
        method,
        JumpSync::Independent,
        4096,
    )
    .expect("plan");
    let mut stepper: XyStepper<3, 4096> =
        XyStepper::new(&disc, &disc, angles(from_mm)).expect("stepper");
    stepper.queue_jump(&jump).expect("queue");
    let f32_galvo = Galvo::<f32>::default();
    let mut last: Option<(u16, u16)> = None;
    let mut max_step = 0;
    for _ in 0..jump.samples() {
        let [x_rad, y_rad] = stepper.step();
        let c = f32_galvo
            .angles_to_codes(kinematics_core::MirrorAngles { x_rad, y_rad })
            .expect("codes");
        if let Some((x, y)) = last {
            max_step = max_step.max(c.x.code.abs_diff(x)).max(c.y.code.abs_diff(y));
        }
        last = Some((c.x.code, c.y.code));
    }
    (jump.samples(), max_step)
}

/// No DAC step larger than the planner's own largest step on the longest
/// jump of the grid (corner to opposite corner): the output never jumps.
fn assert_no_step_beyond_a_planned_jump(samples: &[DacSample]) {
    let (_, bound) = planned_jump(
        (-6.0 * PITCH_MM, 4.0 * PITCH_MM),
        (6.0 * PITCH_MM, -4.0 * PITCH_MM),
        Method::TimeOptimal,
    );
    let largest = samples
        .windows(2)
        .map(|w| {
            w[0].x_code
                .abs_diff(w[1].x_code)
                .max(w[0].y_code.abs_diff(w[1].y_code))
        })
        .max()
        .unwrap_or(0);
    assert!(
        largest <= bound,
        "DAC step {largest} > planned maximum {bound}"
    );
}

#[test]
fn jumps_take_the_planned_time_with_either_planner() {
    let corner = (-6.0 * PITCH_MM, 4.0 * PITCH_MM);
    for (planner, method) in [("optimal", Method::TimeOptimal), ("seed", Method::SEED)] {
        let report = run_to_idle(&format!(
            "target galvo\nplanner {planner}\nset dwell_ms 5\npattern home once\nwait 20\npattern corner once\nwait 40\n"
        ));
        assert_safe_allowing(&report, UNTIL_STEP_FIXES);
        assert!(report.succeeded(false));
        let samples = samples(&report);
        let runs = lit_runs(&samples);
        // From the end of home's laser-off delay to the start of the
        // corner's laser-on delay: idle, then the jump.
        let (home_start, home_len, _) = runs[0];
        let (corner_start, _, _) = runs[1];
        let gap = &samples[home_start + home_len + 10..corner_start - 10];
        let moving = gap
            .windows(2)
            .filter(|w| (w[0].x_code, w[0].y_code) != (w[1].x_code, w[1].y_code))
            .count();
        let first_move = gap
            .windows(2)
            .position(|w| w[0] != w[1])
            .expect("it jumped");
        let landed = gap.len()
            - gap
                .iter()
                .rev()
                .position(|s| *s != gap[gap.len() - 1])
                .unwrap_or(0);
        let (planned, _) = planned_jump((0.0, 0.0), corner, method);
        let measured = landed - first_move;
        // Codes can stand still for a sample at either end (quantisation).
        assert!(
            measured <= planned && measured + 3 >= planned && moving <= planned,
            "{planner}: jump of {measured} samples, planned {planned}"
        );
    }
}

#[test]
fn both_actuators_visit_the_same_points_together() {
    let report = run_to_idle("target both\nset dwell_ms 50\npattern corner once\nwait 1500\n");
    assert_safe_allowing(&report, &[UNTIL_STEP_FIXES, UNTIL_TRAVEL_FIX].concat());
    assert!(report.succeeded(false), "{:?}", report.transcript);
    let gimbal: Vec<(i8, i8)> = report
        .recording
        .dwells
        .iter()
        .filter_map(|d| d.grid)
        .collect();
    assert_eq!(gimbal, spec_patterns::corner());
    let galvo: Vec<(i8, i8)> = lit_runs(&samples(&report))
        .iter()
        .map(|&(_, _, (x, y))| ((x / PITCH_MM).round() as i8, (y / PITCH_MM).round() as i8))
        .collect();
    assert_eq!(galvo, spec_patterns::corner());
    assert!(
        report.recording.laser_events.iter().any(|(_, on)| *on),
        "gimbal laser used"
    );
}

#[test]
fn switching_pattern_mid_dwell_stops_the_galvo_cleanly() {
    let report =
        run_to_idle("target galvo\npattern visit-all\nwait 2500\npattern home once\nwait 1010\n");
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    assert!(report.succeeded(false));
    let samples = samples(&report);
    assert_no_step_beyond_a_planned_jump(&samples);
    let last_lit = lit_runs(&samples).last().map(|r| r.2).expect("lit");
    assert!(
        last_lit.0.abs() < 0.1 && last_lit.1.abs() < 0.1,
        "ends on home: {last_lit:?}"
    );
    assert!(!samples.last().expect("samples").laser);
}

#[test]
fn galvo_commands_refuse_what_it_cannot_do() {
    let report = run_with(
        "pattern tuning once\ntarget both\npattern line 0 0 5 5 once\ntarget galvo\ngoto 30 0\ngalvo status\nstatus\n",
        SimOptions::default(),
    );
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    let errors: Vec<&str> = terminal_lines(&report)
        .into_iter()
        .filter(|l| l.starts_with("error:"))
        .collect();
    assert_eq!(errors.len(), 3, "{errors:?}");
    assert!(
        errors[0].contains("tuning: paths run on one actuator"),
        "{}",
        errors[0]
    );
    assert!(
        errors[1].contains("line: paths run on one actuator"),
        "{}",
        errors[1]
    );
    assert!(
        errors[2].contains("outside the galvo's range"),
        "{}",
        errors[2]
    );
    let lines = terminal_lines(&report);
    assert!(lines.contains(&"galvo: Idle, 0 points queued"), "{lines:?}");
    assert!(lines.contains(&"actuator: galvo"));
    assert!(report.dac.iter().all(|(_, s)| !s.laser));
}

#[test]
fn the_galvo_marks_paths_from_the_command_line() {
    // Circle of 3 cm about (1, -1) cm, counter-clockwise, then the tuning
    // figure (square of 5 cm with its circle and cross).
    let report = run_to_idle(
        "target galvo\npattern circle 1 -1 3 ccw once\nwait 300\npattern tuning 0 0 5 once\nwait 500\n",
    );
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    assert!(report.succeeded(false), "{:?}", report.transcript);
    let samples = samples(&report);
    let runs = lit_runs(&samples);
    assert_eq!(runs.len(), 1 + 4, "one circle stroke, four tuning strokes");
    let (start, len, _) = runs[0];
    // 188 mm of circumference at ≤ 1 m/s.
    assert!(len >= 18_800, "{len} samples");
    for s in &samples[start..start + len] {
        let (x, y) = spot_mm(s);
        let r = (x - 10.0).hypot(y + 10.0);
        assert!(
            (r - 30.0).abs() < 0.15,
            "({x:.3}, {y:.3}) is {r:.3} mm from the centre"
        );
    }
    for &(start, len, _) in &runs[1..] {
        for s in &samples[start..start + len] {
            let (x, y) = spot_mm(s);
            let on_square = (x.abs() - 25.0).abs() < 0.15 && y.abs() <= 25.15
                || (y.abs() - 25.0).abs() < 0.15 && x.abs() <= 25.15;
            let on_circle = (x.hypot(y) - 25.0).abs() < 0.15;
            let on_cross = y.abs() < 0.15 || x.abs() < 0.15;
            assert!(
                on_square || on_circle || on_cross,
                "tuning lit at ({x:.3}, {y:.3})"
            );
        }
    }
}

#[test]
fn switching_pattern_mid_path_brakes_dark_and_moves_on() {
    let report = run_to_idle(
        "target galvo\npattern rect -4 3 4 -3\nwait 20\npattern home once\nwait 1100\n",
    );
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    assert!(report.succeeded(false));
    let samples = samples(&report);
    let runs = lit_runs(&samples);
    assert_eq!(runs.len(), 2, "the interrupted rectangle, then home");
    assert_no_step_beyond_a_planned_jump(&samples);
    let home = runs[1].2;
    assert!(home.0.abs() < 0.1 && home.1.abs() < 0.1, "{home:?}");
}

#[test]
fn a_galvo_loop_too_slow_for_the_sample_rate_is_reported_and_stopped() {
    let report = run_with(
        "target galvo\npattern corner\nwait 200\n",
        SimOptions {
            galvo_cost_ns_per_sample: 12_000,
            ..SimOptions::default()
        },
    );
    assert_safe_allowing(&report, &[UNTIL_STEP_FIXES, UNTIL_GALVO_GATE].concat());
    assert!(report.galvo_underruns > 0);
    assert!(
        report
            .transcript
            .notices
            .iter()
            .any(|(_, n)| n.starts_with("[error: galvo underrun")),
        "{:?}",
        report.transcript.notices
    );
    assert!(report.idle_at_end, "the pattern stopped");
}

#[test]
fn a_galvo_goto_holds_the_point_lit_until_the_next_command() {
    let report = run_to_idle("target galvo\ngoto 2 1\nwait 50\nstatus\nstop\nwait 10\n");
    assert_safe_allowing(&report, &[UNTIL_STEP_FIXES, UNTIL_GALVO_GATE].concat());
    assert!(report.succeeded(false), "{:?}", report.transcript);
    let lines = terminal_lines(&report);
    assert!(
        lines.contains(&"state: goto") && lines.contains(&"phase: holding"),
        "{lines:?}"
    );
    let samples = samples(&report);
    let runs = lit_runs(&samples);
    assert_eq!(runs.len(), 1);
    let (start, len, spot) = runs[0];
    assert!(
        (spot.0 - 20.0).abs() < 0.1 && (spot.1 - 10.0).abs() < 0.1,
        "{spot:?}"
    );
    // Lit from landing until `stop` (~50 ms later), then dark to the end.
    assert!(len >= 4_500, "{len} samples lit");
    assert!(samples[start + len..].iter().all(|s| !s.laser));
}

#[test]
fn random_command_sequences_keep_every_safety_invariant() {
    // Meaningful commands in random order and timing (the same script runs
    // under the safety checker in `safety_campaign.rs`).
    let script = system_tests::random_meaningful_commands();
    let report = run_with(&script, SimOptions::default());
    assert!(report.transcript.script_done, "every line got its reply");
    assert_ne!(report.end, laser_sim::executor::RunEnd::Livelock);
    eprintln!(
        "random commands: {:.2} s simulated, {} DAC samples ({} lit), {} gimbal dwells, {} error replies",
        report.end_time_us as f64 * 1e-6,
        report.dac.len(),
        report.dac.iter().filter(|(_, s)| s.laser).count(),
        report.recording.dwells.len(),
        report.transcript.error_replies
    );
    let lines = terminal_lines(&report);
    let sent = lines.iter().filter(|l| l.starts_with("> ")).count();
    let finals = lines
        .iter()
        .filter(|l| **l == "ok" || l.starts_with("error:"))
        .count();
    assert_eq!(sent, finals, "exactly one closing reply per line");
    assert_eq!(report.galvo_underruns, 0);
    // The galvo's laser is never on while its mirrors move.
    let samples = samples(&report);
    for w in samples.windows(2) {
        if (w[0].x_code, w[0].y_code) != (w[1].x_code, w[1].y_code) && w[0].laser && w[1].laser {
            // Marking moves with the laser on, in steps of at most the
            // marking speed (≤ 3.2 m/s here: 0.032 mm per sample + 1 LSB).
            let (p, q) = (spot_mm(&w[0]), spot_mm(&w[1]));
            assert!((p.0 - q.0).hypot(p.1 - q.1) < 0.2, "lit jump {p:?} → {q:?}");
        }
    }
    assert!(
        !samples.last().expect("samples").laser,
        "galvo dark after stop"
    );
    assert!(
        !report.recording.laser_events.last().is_some_and(|e| e.1),
        "gimbal laser off after stop"
    );
    assert!(
        lines.contains(&"state: idle"),
        "{:?}",
        &lines[lines.len().saturating_sub(20)..]
    );
}
