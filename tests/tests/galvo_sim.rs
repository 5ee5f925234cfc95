//! The galvo in the simulator, end to end: command line → sequencer →
//! galvo loop → simulated DAC, spot from the DAC codes through the exact
//! two-mirror kinematics.

use galvo_planner::{JumpSync, Method, RigidParams, XyIntegrator, plan_xy_jump};
use kinematics_core::{Galvo, PointMm};
use laser_app::galvo::DacSample;
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{
    UNTIL_STEP_FIXES, assert_safe_allowing, lit_sample_times_ns, run_succeeding,
    run_succeeding_with, run_to_idle, run_with, run_with_galvo_cost, sent_at, spec_patterns,
    terminal_lines,
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
    let report = run_succeeding(&format!(
        "target galvo\nset dwell_ms 20\npattern {name} once\nwait {wait_ms}\n"
    ));
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
    let mut integrator: XyIntegrator<3, 4096> =
        XyIntegrator::new(&disc, &disc, angles(from_mm)).expect("integrator");
    integrator.queue_jump(&jump).expect("queue");
    let f32_galvo = Galvo::<f32>::default();
    let mut last: Option<(u16, u16)> = None;
    let mut max_step = 0;
    for _ in 0..jump.samples() {
        let [x_rad, y_rad] = integrator.step();
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
    for (planner, method) in [
        ("optimal", Method::TimeOptimal),
        ("seed", Method::BISECTION),
    ] {
        // The loop's work free: the seed planner's M4 cost underruns
        // (`galvo_cost.rs`), this compares what the planners draw.
        let report = run_succeeding_with(
            &format!(
                "target galvo\nplanner {planner}\nset dwell_ms 5\npattern home once\nwait 20\npattern corner once\nwait 40\n"
            ),
            SimOptions {
                galvo_m4_cost: false,
                ..SimOptions::default()
            },
        );
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
    let report = run_succeeding("target both\nset dwell_ms 50\npattern corner once\nwait 1500\n");
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
    let report = run_succeeding(
        "target galvo\npattern visit-all\nwait 2500\npattern home once\nwait 1010\n",
    );
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
    let report = run_succeeding(
        "target galvo\npattern circle 1 -1 3 ccw once\nwait 300\npattern tuning 0 0 5 once\nwait 500\n",
    );
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
    let report = run_succeeding(
        "target galvo\npattern rect -4 3 4 -3\nwait 20\npattern home once\nwait 1100\n",
    );
    let samples = samples(&report);
    let runs = lit_runs(&samples);
    assert_eq!(runs.len(), 2, "the interrupted rectangle, then home");
    assert_no_step_beyond_a_planned_jump(&samples);
    let home = runs[1].2;
    assert!(home.0.abs() < 0.1 && home.1.abs() < 0.1, "{home:?}");
}

#[test]
fn a_galvo_loop_too_slow_for_the_sample_rate_is_reported_and_stopped() {
    let report = run_with_galvo_cost("target galvo\npattern corner\nwait 200\n", 12_000);
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
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
    let report = run_succeeding("target galvo\ngoto 2 1\nwait 50\nstatus\nstop\nwait 10\n");
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
    // `planner seed` is charged its M4 cost and underruns by design
    // (`galvo_cost.rs`): planned time-optimal here, where the invariant is
    // that no sequence of commands makes the loop late.
    let script =
        system_tests::random_meaningful_commands().replace("planner seed", "planner optimal");
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

/// Lines the terminal sent, with their times (µs).
fn sent_lines(report: &SimReport) -> Vec<(u64, &str)> {
    report
        .transcript
        .lines
        .iter()
        .filter_map(|(t, l)| l.strip_prefix("> ").map(|c| (*t, c)))
        .collect()
}

/// After every `stop`, the galvo's effective laser is dark in every sample
/// output from 1 ms after the line was processed (the simulated USB has no
/// latency: when it was sent) until the next line. Returns the longest
/// stop → lit sample time seen, ns (`None`: none lit at or after a stop),
/// and the lit samples output shortly before the stops (the check is not
/// vacuous when they are many).
fn assert_dark_after_stops(report: &SimReport, label: &str) -> (Option<u64>, usize) {
    let lines = sent_lines(report);
    let samples: Vec<(u64, DacSample)> = report.dac.iter().collect();
    let mut worst_ns = None;
    let mut lit_before = 0;
    for (i, (t_us, line)) in lines.iter().enumerate() {
        if *line != "stop" {
            continue;
        }
        let from_ns = t_us * 1000;
        let until_ns = lines.get(i + 1).map_or(u64::MAX, |(t, _)| t * 1000);
        let start = samples.partition_point(|(t, _)| *t < from_ns);
        lit_before += samples[..start]
            .iter()
            .rev()
            .take(10_000)
            .filter(|(_, s)| s.laser)
            .count();
        for (t, s) in samples[start..].iter().take_while(|(t, _)| *t < until_ns) {
            if s.laser {
                worst_ns = worst_ns.max(Some(t - from_ns));
                assert!(
                    t - from_ns < 1_000_000,
                    "{label}: galvo lit {} µs after `stop` (sent at {t_us} µs)",
                    (t - from_ns) / 1000
                );
            }
        }
    }
    (worst_ns, lit_before)
}

fn galvo_status_line(report: &SimReport) -> String {
    terminal_lines(report)
        .into_iter()
        .rfind(|l| l.starts_with("galvo: "))
        .expect("galvo status answered")
        .to_owned()
}

#[test]
fn stop_reaches_the_galvo_loop_whatever_the_sequencer_thinks() {
    // Issue 9 defect 1: re-aiming a long dwell over and over used to queue
    // a job behind the running one each time, fill the galvo queue, drop
    // the sequencer's run without stopping the loop — and `stop` then sent
    // nothing while the DAC stayed lit for seconds.
    for reaims in [1, 3, 5, 8] {
        let mut script = String::from("target galvo\nset dwell_ms 1000\npattern corner\nwait 5\n");
        for i in 0..reaims {
            script.push_str(if i % 2 == 0 {
                "model seed\n"
            } else {
                "model exact\n"
            });
        }
        script.push_str("stop\nwait 20\ngalvo status\nstatus\nwait 3000\n");
        let report = run_with(&script, SimOptions::default());
        assert!(report.succeeded(false), "{:?}", report.transcript);
        assert!(
            report.transcript.notices.is_empty(),
            "{reaims} re-aims: {:?}",
            report.transcript.notices
        );
        let (worst_ns, lit_before) = assert_dark_after_stops(&report, "re-aimed corner");
        assert!(lit_before > 0, "the galvo was drawing when stopped");
        eprintln!("{reaims} re-aims: last lit sample {worst_ns:?} ns after stop");
        assert_eq!(galvo_status_line(&report), "galvo: Idle, 0 points queued");
        // Re-aiming replaces the job: the point is drawn again, lit, at the
        // same grid corner.
        let runs = lit_runs(&samples(&report));
        let first = runs.first().expect("lit").2;
        assert!(
            runs.iter()
                .all(|r| (r.2.0 - first.0).abs() < 0.1 && (r.2.1 - first.1).abs() < 0.1),
            "{runs:?}"
        );
    }
}

#[test]
fn stop_darkens_the_galvo_within_a_millisecond_at_any_sample_period() {
    // Issue 9 defect 2: halves already handed to the DAC kept drawing
    // after `stop` (up to 313 ms at 1 ms per sample).
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut lit_total = 0;
    for ts_us in [10, 20, 100, 1000] {
        for pattern in ["corner", "circle -3 2 2.5 ccw", "tuning 1 -1 5"] {
            let stop_ms = 1 + next() % 700;
            let script = format!(
                "target galvo\nset galvo.ts_us {ts_us}\nset dwell_ms 300\npattern {pattern}\nwait {stop_ms}\nstop\nwait 600\n"
            );
            let report = run_with(&script, SimOptions::default());
            assert!(report.succeeded(false), "{script}: {:?}", report.transcript);
            let label = format!("ts {ts_us} µs, {pattern}, stop at {stop_ms} ms");
            let (worst_ns, lit_before) = assert_dark_after_stops(&report, &label);
            lit_total += lit_before;
            eprintln!("{label}: last lit sample {worst_ns:?} ns after stop");
        }
    }
    assert!(lit_total > 0, "some stops interrupted a lit drawing");
}

#[test]
fn random_galvo_campaigns_are_dark_within_a_millisecond_of_every_stop() {
    let templates: &[&dyn Fn(u64) -> String] = &[
        &|r| {
            format!(
                "pattern {}{}",
                ["corner", "home", "horizontal", "vertical"][(r % 4) as usize],
                if r % 3 == 0 { " once" } else { "" }
            )
        },
        &|r| {
            format!(
                "pattern {}",
                ["circle -3 2 2.5 ccw", "rect -4 3 4 -3", "tuning 1 -1 5"][(r % 3) as usize]
            )
        },
        &|r| format!("goto {} {}", (r % 17) as f64 - 8.0, (r % 11) as f64 - 5.0),
        &|r| format!("model {}", if r % 2 == 0 { "seed" } else { "exact" }),
        &|r| format!("planner {}", if r % 2 == 0 { "optimal" } else { "seed" }),
        &|r| format!("set dwell_ms {}", r % 800),
        &|r| format!("set galvo.ts_us {}", [10, 20, 50, 1000][(r % 4) as usize]),
        &|r| format!("set galvo.mark_speed_mm_s {}", 200 + r % 3000),
        &|_| "stop".into(),
        &|_| "stop".into(),
        &|r| format!("wait {}", r % 400),
        &|r| format!("wait {}", r % 40),
    ];
    let mut stops = 0;
    for seed in [1u64, 2, 3, 4, 5, 6] {
        let mut x = seed.wrapping_mul(0x2545_f491_4f6c_dd1d) | 1;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut script = format!(
            "target galvo\nset galvo.ts_us {}\n",
            [10, 1000, 20][(seed % 3) as usize]
        );
        for _ in 0..80 {
            let pick = (next() % templates.len() as u64) as usize;
            script.push_str(&templates[pick](next()));
            script.push('\n');
        }
        script.push_str("stop\nwait 300\ngalvo status\n");
        let report = run_with(&script, SimOptions::default());
        assert!(
            report.transcript.script_done,
            "seed {seed}: every line answered"
        );
        let (worst_ns, _) = assert_dark_after_stops(&report, &format!("seed {seed}"));
        stops += sent_lines(&report)
            .iter()
            .filter(|(_, l)| *l == "stop")
            .count();
        eprintln!("seed {seed}: last lit sample {worst_ns:?} ns after a stop");
        assert_eq!(galvo_status_line(&report), "galvo: Idle, 0 points queued");
        assert!(
            !report
                .transcript
                .notices
                .iter()
                .any(|(_, n)| n.contains("not responding")),
            "seed {seed}: {:?}",
            report.transcript.notices
        );
    }
    assert!(stops > 50);
}

#[test]
fn an_idle_galvo_loop_slower_than_the_sample_rate_never_underruns() {
    // Issue 9 defect 3: at 20 µs of loop time per 10 µs sample the idle
    // loop underran hundreds of times a second. Holding, it has nothing
    // to compute.
    for cost_ns in [10_001, 20_000, 200_000] {
        let report = run_with_galvo_cost("wait 3000\ngalvo status\n", cost_ns);
        assert_eq!(report.galvo_underruns, 0, "{cost_ns} ns per sample");
        assert!(report.dac.len() >= 290_000, "the DAC kept outputting");
        // After a job the loop is too slow for, it comes back to a quiet
        // hold too.
        let report = run_with_galvo_cost(
            "target galvo\ngoto 2 1\nwait 50\nstop\nwait 3000\n",
            cost_ns,
        );
        let stop_ns = sent_lines(&report)
            .iter()
            .find(|(_, l)| *l == "stop")
            .map(|(t, _)| t * 1000)
            .expect("stop sent");
        let samples: Vec<(u64, DacSample)> = report.dac.iter().collect();
        let late: Vec<_> = report
            .dac
            .underruns
            .iter()
            .filter(|(at, _)| {
                samples
                    .get(*at)
                    .is_some_and(|(t, _)| *t > stop_ns + 100_000_000)
            })
            .collect();
        assert!(late.is_empty(), "{cost_ns} ns: idle underruns {late:?}");
    }
}

#[test]
fn a_galvo_underrun_replays_dark_and_the_laser_is_dark_at_once() {
    let report = run_with_galvo_cost(
        "target galvo\nset dwell_ms 50\npattern corner\nwait 300\n",
        12_000,
    );
    assert!(report.galvo_underruns > 0);
    let samples: Vec<(u64, DacSample)> = report.dac.iter().collect();
    let &(first, _) = report.dac.underruns.first().expect("an underrun");
    for &(at, halves) in &report.dac.underruns {
        let replayed = &samples[at..(at + halves as usize * 128).min(samples.len())];
        assert!(
            replayed.iter().all(|(_, s)| !s.laser),
            "replay at {at} dark"
        );
    }
    let t0 = samples[first].0;
    assert!(
        samples.iter().all(|(t, s)| *t < t0 + 1_000_000 || !s.laser),
        "dark from 1 ms after the underrun on"
    );
}

#[test]
fn laser_off_keeps_the_galvo_dark_while_it_still_draws() {
    // From the start: the galvo visits every corner, never lit.
    let report =
        run_to_idle("target galvo\nlaser off\nset dwell_ms 20\npattern corner once\nwait 150\n");
    assert!(report.succeeded(false), "{:?}", report.transcript);
    let samples = samples(&report);
    assert!(samples.iter().all(|s| !s.laser), "lit with laser off");
    let corner = (-6.0 * PITCH_MM, 4.0 * PITCH_MM);
    assert!(
        samples.iter().any(|s| {
            let p = spot_mm(s);
            (p.0 - corner.0).abs() <= 0.1 && (p.1 - corner.1).abs() <= 0.1
        }),
        "the mirrors still went to the first corner"
    );

    // Mid-run: dark from three half buffers (the two already handed to
    // the DAC and the one computed and waiting for its slot: 3.84 ms at
    // 100 kHz) after the line is processed; lit again after `laser auto`.
    let report = run_to_idle(
        "target galvo\nset dwell_ms 200\npattern corner once\nwait 100\nlaser off\nwait 400\nlaser auto\nwait 400\n",
    );
    assert!(report.succeeded(false), "{:?}", report.transcript);
    let off_ns = sent_at(&report, "laser off") * 1000;
    let auto_ns = sent_at(&report, "laser auto") * 1000;
    let lit = lit_sample_times_ns(&report);
    assert!(lit.iter().any(|&t| t < off_ns), "lit before laser off");
    assert!(
        lit.iter().all(|&t| t < off_ns + 3_850_000 || t > auto_ns),
        "lit between laser off ({off_ns} ns) and laser auto: {:?}",
        lit.iter()
            .filter(|&&t| t >= off_ns + 3_850_000 && t <= auto_ns)
            .take(3)
            .collect::<Vec<_>>()
    );
    assert!(
        lit.iter().any(|&t| t > auto_ns),
        "lit again after laser auto"
    );
}
