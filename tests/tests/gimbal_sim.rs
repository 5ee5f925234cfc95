//! End-to-end behaviour of the gimbal firmware in the simulator: the real
//! console, sequencer and servo task against simulated FashionStar servos.

use laser_sim::recorder::Direction;
use laser_sim::servo_port::{BusFaults, SilentWindow};
use laser_sim::world::SimOptions;
use system_tests::{
    UNTIL_STEP_FIXES, assert_safe_allowing, run_succeeding, run_to_idle, run_with, sent_at,
    spec_patterns, terminal_lines,
};

/// Pointing tolerance of the exact model, cm (0.5 mm).
const TOLERANCE_CM: f64 = 0.05;
/// SPEC grid pitch, cm.
const PITCH_CM: f64 = 1.916;

fn check_pattern(name: &str, expected: Vec<(i8, i8)>) {
    let report = run_succeeding(&format!("set dwell_ms 50\npattern {name} once\n"));
    let visited: Vec<(i8, i8)> = report
        .recording
        .dwells
        .iter()
        .map(|d| d.grid.expect("grid patterns dwell on grid points"))
        .collect();
    assert_eq!(visited, expected, "{name}: order of visited grid points");
    for d in &report.recording.dwells {
        let (xi, yi) = d.grid.unwrap_or_default();
        let want = (f64::from(xi) * PITCH_CM, f64::from(yi) * PITCH_CM);
        let err = ((d.spot_cm.0 - want.0).powi(2) + (d.spot_cm.1 - want.1).powi(2)).sqrt();
        assert!(
            err <= TOLERANCE_CM,
            "{name}: grid ({xi}, {yi}) spot {:?} is {:.3} mm off",
            d.spot_cm,
            err * 10.0
        );
        assert!(d.laser, "{name}: laser on while dwelling in auto mode");
    }
    // Idle at the end: laser off.
    assert_eq!(
        report.recording.laser_events.last().map(|e| e.1),
        Some(false)
    );
}

#[test]
fn corner_pattern_hits_the_corners_in_order() {
    check_pattern("corner", spec_patterns::corner());
}

#[test]
fn horizontal_and_vertical_patterns() {
    check_pattern("horizontal", spec_patterns::horizontal());
    check_pattern("vertical", spec_patterns::vertical());
}

#[test]
fn visit_all_and_home() {
    check_pattern("visit-all", spec_patterns::visit_all());
    check_pattern("home", vec![(0, 0)]);
}

#[test]
fn full_grid_raster_and_serpentine() {
    check_pattern("grid-full raster", spec_patterns::raster());
    check_pattern("grid-full serpentine", spec_patterns::serpentine());
}

#[test]
fn full_grid_with_one_second_dwells_runs_fast_in_virtual_time() {
    let wall = std::time::Instant::now();
    let report = run_succeeding("pattern grid-full once\n");
    assert_eq!(report.recording.dwells.len(), 13 * 9);
    assert!(report.end_time_us > 117_000_000, "117 dwells of 1 s each");
    // Generous bound: the point is that virtual time does not sleep.
    assert!(wall.elapsed().as_secs_f64() < 60.0);
}

#[test]
fn switching_pattern_mid_dwell_takes_effect_within_one_servo_frame() {
    // The first corner is reached after ~0.3 s; at 1.0 s the gimbal dwells.
    let report = run_succeeding("pattern corner\nwait 1000\npattern home once\n");
    let switched_at = sent_at(&report, "pattern home once");
    let first_frame_after = report
        .recording
        .frames
        .iter()
        .find(|f| f.direction == Direction::Tx && f.t_us >= switched_at)
        .expect("a frame follows the command");
    assert_eq!(
        first_frame_after.bytes[2], 25,
        "the next frame is the sync move"
    );
    // The command line takes ~1.2 ms to cross the simulated USB at the
    // terminal's pace; the move must start within one frame time of that.
    assert!(
        first_frame_after.t_us - switched_at < 3_000,
        "move started {} µs after the command",
        first_frame_after.t_us - switched_at
    );
    let last = report.recording.dwells.last().expect("dwelt on home");
    assert_eq!(last.grid, Some((0, 0)));
}

#[test]
fn stop_turns_the_laser_off_at_once() {
    let report = run_succeeding("pattern visit-all\nwait 2500\nstop\n");
    let stop_at = sent_at(&report, "stop");
    let (t_off, on) = *report
        .recording
        .laser_events
        .last()
        .expect("laser switched");
    assert!(!on);
    assert!(
        t_off >= stop_at && t_off - stop_at < 5_000,
        "off {} µs after stop",
        t_off - stop_at
    );
    assert!(
        report.recording.laser_events.iter().any(|e| e.1),
        "laser was on before"
    );
}

#[test]
fn a_silent_servo_is_a_fault_with_the_laser_off_within_the_timeout() {
    let options = SimOptions {
        faults: BusFaults {
            silent: vec![SilentWindow {
                id: 1,
                from_ms: 1500,
                until_ms: None,
            }],
            ..BusFaults::default()
        },
        ..SimOptions::default()
    };
    let report = run_with("pattern visit-all\nwait 3000\nstatus\n", options);
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    let (t_notice, notice) = report
        .transcript
        .notices
        .iter()
        .find(|(_, n)| n.starts_with("[error: servo 1"))
        .expect("fault notice on the command line")
        .clone();
    assert!(notice.contains("laser off"), "{notice}");
    // The servo goes silent mid-dwell: found by the 100 ms health check,
    // after 3 attempts × 20 ms response timeout.
    assert!(
        (1_500_000..1_700_000).contains(&t_notice),
        "notice at {t_notice} µs"
    );
    let off = report
        .recording
        .laser_events
        .iter()
        .find(|(t, on)| *t >= 1_500_000 && !on)
        .expect("laser switched off");
    assert!(off.0 <= t_notice);
    assert!(
        report
            .transcript
            .lines
            .iter()
            .any(|(_, l)| l == "faults: servo 1 not responding")
    );
    assert!(report.idle_at_end, "the pattern stopped");
}

#[test]
fn garbage_on_the_servo_bus_is_survived() {
    let options = SimOptions {
        faults: BusFaults {
            corrupt_probability: 0.02,
            ..BusFaults::default()
        },
        ..SimOptions::default()
    };
    let report = run_with("set dwell_ms 50\npattern corner once\n", options);
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    assert!(report.succeeded(false), "{:?}", report.transcript.notices);
    assert_eq!(report.recording.dwells.len(), 4);
}

#[test]
fn a_thousand_random_command_lines_never_wedge_the_command_line() {
    let words = [
        "pattern",
        "corner",
        "once",
        "goto",
        "grid",
        "set",
        "get",
        "dwell_ms",
        "laser",
        "on",
        "off",
        "model",
        "seed",
        "exact",
        "stop",
        "status",
        "params",
        "help",
        "-3",
        "2.5",
        "1e9",
        "nan",
        "rect",
        "circle",
        "line",
        "xyzzy",
        "\t",
        "#",
        "oq_cm",
        "99",
        "-0",
        "grid-full",
    ];
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut script = String::from("set dwell_ms 0\n");
    for _ in 0..1000 {
        let n = (next() % 6) as usize;
        let line: Vec<&str> = (0..n)
            .map(|_| words[(next() % words.len() as u64) as usize])
            .collect();
        script.push_str(&line.join(" "));
        script.push('\n');
    }
    script.push_str("stop\nstatus\n");
    let report = run_with(&script, SimOptions::default());
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    assert!(report.transcript.script_done, "every line got its reply");
    let sent = report
        .transcript
        .lines
        .iter()
        .filter(|(_, l)| l.starts_with("> "))
        .count();
    let finals = report
        .transcript
        .lines
        .iter()
        .filter(|(_, l)| l == "ok" || l.starts_with("error:"))
        .count();
    assert_eq!(sent, finals, "exactly one closing reply per line");
    assert!(
        report.transcript.error_replies > 100,
        "invalid lines were refused"
    );
    assert!(report.idle_at_end);
}

#[test]
fn a_circle_is_drawn_on_its_path_and_closes() {
    // Radius 4 cm about (2, 1) cm, 0.2 cm steps, no dwell between steps.
    let report = run_succeeding("pattern circle 2 1 4 ccw once\nwait 2500\n");
    let drawn: Vec<_> = report.recording.spot.iter().filter(|s| s.laser).collect();
    let first_on_circle = drawn
        .iter()
        .position(|s| (((s.x_cm - 2.0).powi(2) + (s.y_cm - 1.0).powi(2)).sqrt() - 4.0).abs() < 0.1)
        .expect("the spot reaches the circle");
    let mut octants = [false; 8];
    for s in &drawn[first_on_circle..] {
        let (dx, dy) = (s.x_cm - 2.0, s.y_cm - 1.0);
        let off = ((dx * dx + dy * dy).sqrt() - 4.0).abs();
        // Half a step of interpolation, joint-space chords between points
        // and 0.1° servo resolution.
        assert!(
            off < 0.15,
            "spot ({:.3}, {:.3}) is {:.2} mm off the circle",
            s.x_cm,
            s.y_cm,
            off * 10.0
        );
        let octant =
            ((dy.atan2(dx) + std::f64::consts::PI) / (std::f64::consts::PI / 4.0)) as usize;
        octants[octant.min(7)] = true;
    }
    assert!(
        octants.iter().all(|o| *o),
        "the whole circle was drawn: {octants:?}"
    );
    // The servos end on the last point, the circle's top (its start).
    let end = report.recording.spot.last().expect("spot sampled");
    assert!(
        (end.x_cm - 2.0).abs() < 0.05 && (end.y_cm - 5.0).abs() < 0.05,
        "ends at {end:?}"
    );
}

#[test]
fn saved_settings_survive_a_reboot_and_a_corrupt_record_falls_back_to_defaults() {
    let first = run_with(
        "pattern corner\nsave\nstop\nset dwell_ms 123\nset oq_cm 30\nsave\n",
        SimOptions::default(),
    );
    assert_safe_allowing(&first, UNTIL_STEP_FIXES);
    assert_eq!(
        first.transcript.error_replies, 1,
        "save is refused while a pattern runs: {:?}",
        first.transcript.lines
    );
    let record = first.saved_settings.expect("save wrote a record");
    let rebooted = run_with(
        "get dwell_ms\nget oq_cm\n",
        SimOptions {
            saved_settings: Some(record.clone()),
            ..SimOptions::default()
        },
    );
    assert_safe_allowing(&rebooted, UNTIL_STEP_FIXES);
    let lines = terminal_lines(&rebooted);
    assert!(
        lines.iter().any(|l| l.starts_with("dwell_ms = 123")),
        "{lines:?}"
    );
    assert!(
        lines.iter().any(|l| l.starts_with("oq_cm = 30")),
        "{lines:?}"
    );
    let mut corrupt = record;
    corrupt[12] ^= 0x40;
    let fallback = run_with(
        "get dwell_ms\npattern home once\n",
        SimOptions {
            saved_settings: Some(corrupt),
            ..SimOptions::default()
        },
    );
    assert_safe_allowing(&fallback, UNTIL_STEP_FIXES);
    assert!(fallback.succeeded(false));
    assert!(
        fallback
            .transcript
            .lines
            .iter()
            .any(|(_, l)| l.starts_with("dwell_ms = 1000"))
    );
}

#[test]
fn servo_ids_from_the_settings_are_used_on_the_bus() {
    // No servo answers at id 7: the goto faults instead of silently using id 0.
    let report = run_with(
        "set yaw.id 7\ngoto 3 2\nwait 500\nstatus\n",
        SimOptions::default(),
    );
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    assert!(
        report
            .transcript
            .notices
            .iter()
            .any(|(_, n)| n.starts_with("[error: servo 7")),
        "{:?}",
        report.transcript.notices
    );
    let tx_ids: Vec<u8> = report
        .recording
        .frames
        .iter()
        .filter(|f| f.direction == Direction::Tx && f.bytes[2] == 10)
        .map(|f| f.bytes[4])
        .collect();
    assert!(
        tx_ids.contains(&7),
        "angle queries went to servo 7: {tx_ids:?}"
    );
    // Dark at the end (travel to a goto is dark, so it may never have lit).
    assert_ne!(
        report.recording.laser_events.last().map(|e| e.1),
        Some(true),
        "{:?}",
        report.recording.laser_events
    );
}

#[test]
fn goto_holds_the_point_with_the_seed_model_off_by_its_known_error() {
    // Bottom-right corner: the seed model errs by ~13.9 mm here (kin grid-error).
    let exact = run_to_idle("goto 11.496 -7.664\nwait 500\n");
    assert_safe_allowing(&exact, UNTIL_STEP_FIXES);
    let seed = run_to_idle("model seed\ngoto 11.496 -7.664\nwait 500\n");
    assert_safe_allowing(&seed, UNTIL_STEP_FIXES);
    let end = |r: &laser_sim::world::SimReport| {
        let s = r.recording.spot.last().expect("spot sampled");
        ((s.x_cm - 11.496).powi(2) + (s.y_cm + 7.664).powi(2)).sqrt() * 10.0
    };
    assert!(
        end(&exact) < 0.5,
        "exact model off by {:.2} mm",
        end(&exact)
    );
    assert!(
        (end(&seed) - 13.9).abs() < 1.0,
        "seed model off by {:.2} mm",
        end(&seed)
    );
}

#[test]
fn a_servo_that_answers_again_is_reported_recovered_and_patterns_run_again() {
    let options = SimOptions {
        faults: BusFaults {
            silent: vec![SilentWindow {
                id: 0,
                from_ms: 1500,
                until_ms: Some(2500),
            }],
            ..BusFaults::default()
        },
        ..SimOptions::default()
    };
    let report = run_with(
        "pattern corner\nwait 3500\nset dwell_ms 50\npattern corner once\n",
        options,
    );
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    let notice_at = |prefix: &str| {
        system_tests::notice_at(&report, prefix)
            .unwrap_or_else(|| panic!("no {prefix} notice in {:?}", report.transcript.notices))
    };
    let fault = notice_at("[error: servo 0");
    let recovered = notice_at("[info: servo 0 answering again");
    assert!(fault < 1_700_000, "fault at {fault} µs");
    // Faulty servos are pinged every 500 ms.
    assert!(
        (2_500_000..3_100_000).contains(&recovered),
        "recovered at {recovered} µs"
    );
    assert!(report.succeeded(false), "{:?}", report.transcript);
    let after: Vec<_> = report
        .recording
        .dwells
        .iter()
        .filter(|d| d.t_us > recovered)
        .filter_map(|d| d.grid)
        .collect();
    assert_eq!(after, vec![(-6, 4), (6, 4), (6, -4), (-6, -4)]);
}

#[test]
fn laser_stays_off_while_idle_and_in_dwell_mode_lights_only_the_points() {
    let report =
        run_succeeding("laser on\nwait 300\nlaser dwell\nset dwell_ms 100\npattern corner once\n");
    let started = sent_at(&report, "pattern corner once");
    assert!(
        report
            .recording
            .laser_events
            .iter()
            .all(|&(t, on)| !on || t >= started),
        "never on before a pattern runs: {:?}",
        report.recording.laser_events
    );
    let corners: Vec<(f64, f64)> = spec_patterns::corner()
        .into_iter()
        .map(|(xi, yi)| (f64::from(xi) * PITCH_CM, f64::from(yi) * PITCH_CM))
        .collect();
    let lit: Vec<_> = report.recording.spot.iter().filter(|s| s.laser).collect();
    assert!(!lit.is_empty(), "the laser lit the points");
    for s in lit {
        let nearest = corners
            .iter()
            .map(|c| ((s.x_cm - c.0).powi(2) + (s.y_cm - c.1).powi(2)).sqrt())
            .fold(f64::INFINITY, f64::min);
        // Within the 0.5° arrival deadband of a corner (~3 mm at 30 cm).
        assert!(
            nearest < 0.35,
            "lit {:.2} cm from the nearest corner",
            nearest
        );
    }
}

#[test]
fn the_trace_has_a_row_at_every_laser_change_and_ends_in_the_final_state() {
    for script in [
        "pattern corner once\n",
        "laser dwell\npattern home once\n",
        "goto 3 2\nwait 300\nstop\nwait 7\n",
    ] {
        let report = run_to_idle(script);
        let csv = report.recording.trace_csv();
        let rows: Vec<(u64, bool)> = csv
            .lines()
            .skip(1)
            .map(|line| {
                let f: Vec<&str> = line.split(',').collect();
                let t_ms: f64 = f[0].parse().expect("t_ms");
                ((t_ms * 1000.0).round() as u64, f[3] == "1")
            })
            .collect();
        let events = &report.recording.laser_events;
        assert!(events.iter().any(|e| e.1), "{script}: the laser was used");
        for &(t_us, on) in events {
            assert!(
                rows.contains(&(t_us, on)),
                "{script}: no trace row for the laser turning {} at {t_us} µs",
                if on { "on" } else { "off" }
            );
        }
        // Rows in time order; the last row of each instant has the state
        // the laser was left in at that instant.
        assert!(rows.windows(2).all(|w| w[0].0 <= w[1].0));
        for (i, &(t_us, laser)) in rows.iter().enumerate() {
            if rows.get(i + 1).is_some_and(|next| next.0 == t_us) {
                continue;
            }
            assert_eq!(
                laser,
                report.recording.laser_at(t_us),
                "{script}: row at {t_us} µs"
            );
        }
        let &(last_t, last_laser) = rows.last().expect("rows");
        assert_eq!(
            last_t, report.end_time_us,
            "{script}: the trace reaches the end"
        );
        assert!(!last_laser, "{script}: ends dark");
        assert_eq!(Some(last_laser), events.last().map(|e| e.1));
    }
}
