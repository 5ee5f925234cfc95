//! G-code on the stepper pan/tilt in the simulator (issues 12 and 13):
//! a soft reset halts the steps at once, a feed hold brakes at once from
//! the segment being executed, the feed override applies on the fly, the
//! laser power path, `$H` answered when homing ends, and `$11` saved.

use laser_sim::stepper::{StepEdge, StepPin};
use laser_sim::world::{SimOptions, SimReport};
use system_tests::gcode_job::{Piece, fit};
use system_tests::gcode_toolpath::{gimbal_spot_mm, lit_mm};
use system_tests::{gimbal_dark_after, run_with, sent_at, terminal_lines};

/// Runs `script` on `target stepper` with default options.
fn run(script: &str) -> SimReport {
    run_with(&format!("target stepper\n{script}"), SimOptions::default())
}

/// Time the terminal sent realtime byte `byte`, µs.
fn realtime_at(report: &SimReport, byte: u8) -> u64 {
    let tag = format!(">> 0x{byte:02x}");
    report
        .transcript
        .lines
        .iter()
        .find(|(_, l)| *l == tag)
        .map(|(t, _)| *t)
        .unwrap_or_else(|| panic!("{tag} was not sent"))
}

/// Rising STEP edges of axis `axis`, ns.
fn step_times_ns(report: &SimReport, axis: u8) -> Vec<u64> {
    report
        .stepper
        .edges
        .iter()
        .filter(|e: &&StepEdge| e.axis == axis && e.pin == StepPin::Step && e.high)
        .map(|e| e.t_ns)
        .collect()
}

/// The spot (mm) at `t_us` (the last sample at or before it).
fn spot_mm_at(report: &SimReport, t_us: u64) -> [f64; 2] {
    let s = report
        .recording
        .spot
        .iter()
        .rev()
        .find(|s| s.t_us <= t_us)
        .expect("a spot sample");
    [s.x_cm * 10.0, s.y_cm * 10.0]
}

/// `MPos:x,y` of a status report, mm.
fn mpos(status: &str) -> [f64; 2] {
    let field = status
        .split('|')
        .find_map(|f| f.strip_prefix("MPos:"))
        .unwrap_or_else(|| panic!("no MPos in {status}"));
    let v: Vec<f64> = field
        .split(',')
        .map(|n| n.parse().expect("a number"))
        .collect();
    [v[0], v[1]]
}

/// The status reports of the transcript.
fn statuses(report: &SimReport) -> Vec<&str> {
    terminal_lines(report)
        .into_iter()
        .filter(|l| l.starts_with('<'))
        .collect()
}

fn dist(p: [f64; 2], q: [f64; 2]) -> f64 {
    (p[0] - q[0]).hypot(p[1] - q[1])
}

#[test]
fn a_soft_reset_mid_move_halts_the_steps_at_once_dark_with_alarm_3() {
    for feed in [1200, 3000] {
        let report = run(&format!(
            "G0 X-40 Y0\nG1 X40 F{feed} M3 S1000\nwait 1000\n@realtime 0x18\nwait 500\n?\n"
        ));
        let reset_us = realtime_at(&report, 0x18);
        let pan = step_times_ns(&report, 0);
        let before: Vec<u64> = pan
            .iter()
            .copied()
            .filter(|&t| t <= reset_us * 1000)
            .collect();
        let after = pan.len() - before.len();
        let n = before.len();
        assert!(n > 10, "F{feed}: it was stepping");
        let period_ns = before[n - 1] - before[n - 2];
        let last_ns = *pan.last().expect("steps");
        eprintln!(
            "F{feed}: step period {period_ns} ns at the reset; {after} pan steps after it, the last {} ns after",
            last_ns.saturating_sub(reset_us * 1000)
        );
        // Halted by the step timer's next event: at most one more step.
        assert!(after <= 1, "F{feed}: {after} steps after the reset");
        assert!(last_ns <= reset_us * 1000 + period_ns, "F{feed}");
        assert!(
            gimbal_dark_after(&report, reset_us) <= 1_000,
            "F{feed}: laser dark within 1 ms"
        );
        let lines = terminal_lines(&report);
        assert!(lines.contains(&"ALARM:3"), "F{feed}: {lines:?}");
        // MPos from the counted steps: where the spot is.
        let status = statuses(&report).pop().expect("a status report");
        assert!(status.starts_with("<Alarm|"), "{status}");
        let spot = spot_mm_at(&report, report.end_time_us);
        assert!(dist(mpos(status), spot) < 0.01, "{status} vs {spot:?}");
        assert!(
            spot[0] > -35.0 && spot[0] < 35.0,
            "stopped mid-line: {spot:?}"
        );
    }
}

/// The stepper's acceleration limit in pan steps/s² (default settings:
/// 900 °/s² at 0.05625° per step).
const ACCEL_STEPS_S2: f64 = 900.0 / 0.05625;

/// Every change of the step rate of `axis` within the acceleration
/// limit, from `from_ns` on: the step intervals grouped into constant-rate
/// segments, successive segments' rates differ by at most the limit over
/// their mean duration (a timer tick of rounding allowed).
fn assert_within_accel(report: &SimReport, axis: u8, from_ns: u64) {
    let times: Vec<u64> = step_times_ns(report, axis)
        .into_iter()
        .filter(|&t| t >= from_ns)
        .collect();
    // (rate steps/s, duration s) of each run of equal intervals (±1 µs).
    let mut segments: Vec<(f64, f64)> = Vec::new();
    let mut last_ns = 0;
    for w in times.windows(2) {
        let dt_ns = w[1] - w[0];
        match segments.last_mut() {
            Some((_, total)) if dt_ns.abs_diff(last_ns) <= 1_000 => *total += dt_ns as f64 / 1e9,
            _ => segments.push((1e9 / dt_ns as f64, dt_ns as f64 / 1e9)),
        }
        last_ns = dt_ns;
    }
    for w in segments.windows(2) {
        let ((r0, t0), (r1, t1)) = (w[0], w[1]);
        // A pause (a new move from rest, a dwell) is no deceleration.
        if t0 > 0.1 || t1 > 0.1 {
            continue;
        }
        let allowed = ACCEL_STEPS_S2 * (t0 + t1) / 2.0 * 1.01 + (r0 * r0 + r1 * r1) / 1e6;
        assert!(
            (r1 - r0).abs() <= allowed,
            "rate {r0:.1} -> {r1:.1} steps/s (allowed {allowed:.1})"
        );
    }
}

#[test]
fn a_feed_hold_brakes_at_once_dark_and_resumes_where_it_stopped() {
    for feed in [1200.0, 3000.0] {
        let report = run(&format!(
            "G0 X-40 Y0\nG1 X40 F{feed} M3 S1000\nwait 1000\n!\nwait 400\n?\nwait 400\n?\n~\nG4 P0.2\n"
        ));
        let (hold_at, resume_at) = (
            system_tests::sent_at(&report, "!"),
            system_tests::sent_at(&report, "~"),
        );
        let states = statuses(&report);
        assert!(
            states.iter().all(|s| s.starts_with("<Hold:0|")),
            "{states:?}"
        );
        assert_eq!(mpos(states[0]), mpos(states[1]), "held still");
        assert!(
            gimbal_dark_after(&report, hold_at) <= 1_000,
            "F{feed}: dark within 1 ms of the hold"
        );
        let lit_in_hold = report
            .recording
            .spot
            .iter()
            .any(|s| s.laser && s.t_us > hold_at + 1_000 && s.t_us < resume_at);
        assert!(!lit_in_hold, "F{feed}: lit during the hold");
        // The dark stretch: from the spot at `!` to where it came to rest.
        let (at_hold, at_rest) = (spot_mm_at(&report, hold_at), spot_mm_at(&report, resume_at));
        let dark_mm = dist(at_hold, at_rest);
        let resumed = step_times_ns(&report, 0)
            .iter()
            .any(|&t| t > resume_at * 1000);
        let v = feed / 60.0;
        eprintln!(
            "F{feed}: {dark_mm:.3} mm travelled dark after the hold ({} µs to rest)",
            step_times_ns(&report, 0)
                .into_iter()
                .rev()
                .find(|&t| t < resume_at * 1000)
                .map_or(0, |t| t / 1000 - hold_at)
        );
        // One step of the running segment (≈ 0.25 mm at 25 cm) and v²/2a
        // (≤ 1.25 steps at 50 mm/s) at most.
        assert!(dark_mm <= 0.75, "F{feed}: {dark_mm} mm dark ({v} mm/s)");
        assert!(resumed, "F{feed}: steps again after the resume");
        assert_within_accel(&report, 0, hold_at * 1000);
        // Resumed from exactly where it stopped, the whole line drawn.
        let pieces = [Piece::Line {
            a: [-40.0, 0.0],
            b: [40.0, 0.0],
        }];
        let fit = fit(&lit_mm(&gimbal_spot_mm(&report)), &pieces);
        eprintln!("F{feed}: {fit:?}");
        assert!(fit.worst_missed_mm <= 0.5, "F{feed}: {fit:?}");
        for axis in &report.stepper.axes {
            assert!(axis.stalls().is_empty(), "{}", report.stepper.report());
        }
    }
}

/// Spot speed over the 100 ms after `t_us`, mm/s.
fn speed_after(report: &SimReport, t_us: u64) -> f64 {
    dist(spot_mm_at(report, t_us), spot_mm_at(report, t_us + 100_000)) / 0.1
}

#[test]
fn the_feed_override_changes_the_stepper_speed_mid_block() {
    // Spaced: the console queues 8 realtime commands at a time.
    let down = "@realtime 0x92\nwait 10\n".repeat(5);
    let up = "@realtime 0x91\nwait 10\n".repeat(10);
    let report = run(&format!(
        "G0 X-60 Y0\nG1 X60 F1200 M3 S1000\nwait 1000\n{down}wait 1000\n{up}wait 1000\n?\nG4 P0.1\n"
    ));
    system_tests::assert_all_ok(&report, "override");
    let times: Vec<u64> = report
        .transcript
        .lines
        .iter()
        .filter(|(_, l)| l.starts_with(">> 0x9"))
        .map(|(t, _)| *t)
        .collect();
    let (down_at, up_at) = (times[4], times[14]);
    let before = speed_after(&report, down_at - 200_000);
    // The prepared segments (≤ 8 steps ≈ 100 ms at 20 mm/s), then the
    // new cruise.
    let slow = speed_after(&report, down_at + 200_000);
    let fast = speed_after(&report, up_at + 200_000);
    eprintln!("speed {before:.2} → {slow:.2} (50 %) → {fast:.2} mm/s (150 %)");
    assert!((before - 20.0).abs() < 1.0, "{before}");
    assert!((slow - 10.0).abs() < 0.6, "{slow}");
    assert!((fast - 30.0).abs() < 1.5, "{fast}");
    // The change shows within ≈ 100 ms (one line block, no new block).
    let first_slow = speed_after(&report, down_at + 100_000);
    assert!(first_slow < 12.0, "{first_slow}");
    let status = statuses(&report).pop().expect("a status");
    assert!(status.contains("|Ov:150,"), "{status}");
    assert_within_accel(&report, 0, 0);
    for axis in &report.stepper.axes {
        assert!(axis.stalls().is_empty(), "{}", report.stepper.report());
    }
}

/// A run with a pan homing switch closing at `switch_deg` (towards
/// positive angles), the pan axis powered up at 0°.
fn run_with_pan_switch(script: &str, switch_deg: f64) -> SimReport {
    run_with(
        &format!(
            "set stepper.pan.home_dir 1\nset stepper.pan.home_deg {switch_deg}\ntarget stepper\n{script}"
        ),
        SimOptions {
            stepper_switches: [
                Some(laser_sim::stepper::LimitSwitch {
                    closes_at_deg: switch_deg,
                    towards_positive: true,
                    hysteresis_deg: 0.4,
                }),
                None,
            ],
            ..SimOptions::default()
        },
    )
}

/// Time of the first line after `> sent` that satisfies `is`, µs, and
/// the line.
fn first_after(report: &SimReport, sent: &str, is: impl Fn(&str) -> bool) -> (u64, String) {
    let lines = &report.transcript.lines;
    let from = lines
        .iter()
        .position(|(_, l)| l.strip_prefix("> ") == Some(sent))
        .unwrap_or_else(|| panic!("{sent:?} not sent"));
    lines[from..]
        .iter()
        .find(|(_, l)| is(l))
        .cloned()
        .unwrap_or_else(|| panic!("nothing after {sent:?}"))
}

#[test]
fn dollar_h_on_the_stepper_answers_when_homing_has_ended() {
    // A sender streams `$H` and the job behind it without waiting.
    let report = run_with_pan_switch(
        "@type-ahead $H\n@type-ahead G1 X10 F600 M3 S1000\n@type-ahead G1 X20\nG4 P0.2\n",
        30.0,
    );
    system_tests::assert_all_ok(&report, "$H then G1s");
    let (homed_at, _) = first_after(&report, "$H", |l| l.starts_with("[homed: stepper"));
    let (ok_at, reply) = first_after(&report, "$H", |l| l == "ok" || l.starts_with("error"));
    assert_eq!(reply, "ok");
    eprintln!("$H: homed at {homed_at} µs, ok at {ok_at} µs");
    assert!(ok_at >= homed_at, "ok before homing ended");
    // Homing takes seconds: seek 30° at 20 °/s, latch, pull-off.
    assert!(ok_at > 1_500_000, "{ok_at}");
    // Nothing of the G1s moved before the reply: the spot is where
    // homing left it, then it draws the job.
    assert_eq!(spot_mm_at(&report, homed_at), spot_mm_at(&report, ok_at));
    let end = spot_mm_at(&report, report.end_time_us);
    assert!(dist(end, [20.0, 0.0]) < 0.3, "{end:?}");
    assert!(
        report
            .recording
            .spot
            .iter()
            .filter(|s| s.laser)
            .all(|s| s.t_us >= ok_at),
        "lit only in the G1s (from the first one's start on: the line starts where homing left the spot)"
    );
}

#[test]
fn a_failed_dollar_h_raises_alarm_9_before_its_reply_and_locks() {
    // The switch lies beyond the travel: never found.
    let report = run_with_pan_switch("$H\nG1 X10 F600\n", 170.0);
    let lines = terminal_lines(&report);
    let h = lines.iter().position(|l| *l == "> $H").expect("sent");
    let after: Vec<&str> = lines[h + 1..]
        .iter()
        .copied()
        .filter(|l| !l.starts_with('[') && !l.starts_with("Grbl "))
        .collect();
    eprintln!("{after:?}");
    assert_eq!(&after[..3], ["ALARM:9", "ok", "> G1 X10 F600"]);
    assert_eq!(after[3], "error:9", "locked by the alarm");
}

/// The `$11=` line of the last `$$` listing.
fn dollar_11(report: &SimReport) -> String {
    terminal_lines(report)
        .into_iter()
        .rev()
        .find(|l| l.starts_with("$11="))
        .unwrap_or_else(|| panic!("no $11 line: {:?}", terminal_lines(report)))
        .to_string()
}

#[test]
fn dollar_11_is_checked_listed_saved_and_survives_a_reset_and_a_reboot() {
    let report = run_with(
        "$11=0.05\n$11=-1\n$11=11\n$$\nsave\n@realtime 0x18\n$$\n",
        SimOptions::default(),
    );
    let lines = terminal_lines(&report);
    let replies: Vec<&str> = lines
        .iter()
        .copied()
        .filter(|l| *l == "ok" || l.starts_with("error"))
        .collect();
    // 0.05 accepted, −1 (negative: error:4) and 11 (range 0–10 mm) refused.
    assert_eq!(&replies[..3], ["ok", "error:4", "error:3"], "{lines:?}");
    assert_eq!(dollar_11(&report), "$11=0.050");
    let rebooted = run_with(
        "$$\n",
        SimOptions {
            settings_flash: Some(report.settings_flash.clone()),
            ..SimOptions::default()
        },
    );
    assert_eq!(dollar_11(&rebooted), "$11=0.050");
    let fresh = run_with("$$\n", SimOptions::default());
    assert_eq!(dollar_11(&fresh), "$11=0.010");
}

/// A zig-zag of 20 90° corners, 5 mm legs, at F`feed` (mm/min), after
/// `prefix`; seconds from its first G1.
fn zigzag_with(prefix: &str, target: &str, feed: u32) -> f64 {
    let first = format!("G1 F{feed} M3 S1000");
    let mut script = format!("{prefix}target {target}\nG0 X0 Y0\n{first}\n");
    for k in 1..=20 {
        let (x, y) = (5.0 * ((k + 1) / 2) as f64, 5.0 * (k / 2) as f64);
        script.push_str(&format!("G1 X{x} Y{y}\n"));
    }
    script.push_str("G4 P0.1\n");
    let report = run_with(&script, SimOptions::default());
    system_tests::assert_all_ok(&report, target);
    let start = system_tests::sent_at(&report, &first);
    (report.end_time_us - start) as f64 / 1e6
}

#[test]
fn dollar_11_sets_the_corner_speed_on_every_actuator() {
    // The galvo at its marking speed (1 m/s), where corners cost time.
    for (target, feed) in [("gimbal", 3000), ("stepper", 3000), ("galvo", 60_000)] {
        let tight = zigzag_with("$11=0.002\n", target, feed);
        let loose = zigzag_with("$11=2\n", target, feed);
        eprintln!("{target}: 20 corners at $11=0.002 {tight:.3} s, at $11=2 {loose:.3} s");
        assert!(loose < tight * 0.95, "{target}: {tight} vs {loose}");
    }
}

/// How long the laser ran at `level` ‰, µs.
fn time_at_level(report: &SimReport, level: u16) -> u64 {
    let changes = &report.recording.laser_power;
    changes
        .iter()
        .enumerate()
        .filter(|(_, c)| c.1 == level)
        .map(|(k, c)| changes.get(k + 1).map_or(report.end_time_us, |n| n.0) - c.0)
        .sum()
}

#[test]
fn s_and_the_power_override_set_the_duty_on_the_stepper_where_the_blocks_are() {
    let report = run(
        "$30=1000\n$31=0\nG0 X-20 Y0\nG1 X0 F600 M3 S300\nG1 X20 S1000\n\
         G1 X40 S500\nwait 500\n@realtime 0x9b\n@realtime 0x9d\nwait 6000\nM5\n",
    );
    let levels: Vec<(u64, u16)> = report.recording.laser_power.clone();
    eprintln!("levels (µs, ‰): {levels:?}");
    // S300, from 0.5 s −11 %: 267; then S1000 and S500 at 89 %.
    let order: Vec<u16> = levels.iter().map(|l| l.1).collect();
    assert_eq!(order, [300, 267, 890, 445, 0], "{levels:?}");
    // Each S from where its block starts (20 mm at 10 mm/s: 2 s each).
    for (&(t, level), x) in levels[2..4].iter().zip([0.0, 20.0]) {
        let at = spot_mm_at(&report, t);
        assert!(dist(at, [x, 0.0]) < 0.3, "{level} ‰ from {at:?}");
    }
    assert!(time_at_level(&report, 890) > 1_900_000, "{levels:?}");
    assert!(time_at_level(&report, 445) > 1_900_000, "{levels:?}");
    assert_eq!(report.recording.power_at(report.end_time_us), 0, "M5: dark");
}

#[test]
fn m4_on_the_stepper_lights_while_it_steps_and_is_dark_at_rest_and_in_dwells() {
    let report = run("G0 X-20 Y0\nG1 X0 F600 M4 S600\nG4 P0.5\nG1 X20\nG4 P0.3\n");
    let levels: Vec<(u64, u16)> = report.recording.laser_power.clone();
    eprintln!("M4 levels (µs, ‰): {levels:?}");
    let lit: Vec<_> = report
        .recording
        .laser_events
        .iter()
        .filter(|e| e.1)
        .collect();
    assert_eq!(
        lit.len(),
        2,
        "two lit moves: {:?}",
        report.recording.laser_events
    );
    assert!(levels.iter().all(|l| l.1 <= 600), "{levels:?}");
    // Dark through the dwell between them (0.5 s).
    let dwell = system_tests::sent_at(&report, "G4 P0.5");
    let dark: u64 = report
        .recording
        .laser_events
        .windows(2)
        .filter(|w| !w[0].1 && w[0].0 > dwell)
        .map(|w| w[1].0 - w[0].0)
        .next()
        .expect("a dark stretch");
    assert!(dark >= 450_000, "{dark} µs dark in the dwell");
}

/// Pan step rate at `t_ns` (the interval of the steps around it),
/// steps/s; 0 outside the steps.
fn pan_rate_at(steps_ns: &[u64], t_ns: u64) -> f64 {
    let k = steps_ns.partition_point(|&s| s <= t_ns);
    match (
        k.checked_sub(1).and_then(|i| steps_ns.get(i)),
        steps_ns.get(k),
    ) {
        (Some(&a), Some(&b)) => 1e9 / (b - a) as f64,
        _ => 0.0,
    }
}

#[test]
fn m4_power_on_the_stepper_follows_its_speed_through_the_ramps_and_m3_stays_constant() {
    // Slow ramps (10 °/s²: about half a second to 20 mm/s) on a line
    // along the pan axis.
    let job = |mode: &str| {
        run(&format!(
            "$30=1000\n$31=0\nset stepper.accel_deg_s2 10\nG0 X-40 Y0\n\
             G1 X40 F1200 {mode} S800\nG4 P0.5\nM5\n"
        ))
    };
    let report = job("M4");
    let levels = report.recording.laser_power.clone();
    eprintln!("M4 levels (µs, ‰): {levels:?}");
    // The G1's steps (from its first lit level on).
    let start_ns = levels.first().expect("lit").0.saturating_sub(2_000) * 1000;
    let steps: Vec<u64> = step_times_ns(&report, 0)
        .into_iter()
        .filter(|&t| t >= start_ns)
        .collect();
    let cruise = steps.windows(2).map(|w| w[1] - w[0]).min().expect("steps");
    let cruise_rate = 1e9 / cruise as f64;
    let (mut rising, mut falling) = (0, 0);
    let lit: Vec<_> = levels.iter().filter(|l| l.1 > 0).collect();
    for w in lit.windows(2) {
        let (t, level) = *w[0];
        let ratio = pan_rate_at(&steps, t * 1000) / cruise_rate;
        let duty = f64::from(level) / 800.0;
        eprintln!("{t} µs: duty/S {duty:.3}, speed/F {ratio:.3}");
        assert!(level <= 800, "{levels:?}");
        if (0.15..0.95).contains(&ratio) {
            assert!(
                (duty - ratio).abs() <= 0.1 * ratio,
                "{t} µs: {duty} vs {ratio}"
            );
            if w[1].1 > level {
                rising += 1;
            } else {
                falling += 1;
            }
        }
    }
    assert!(
        rising >= 5 && falling >= 5,
        "{rising} up, {falling} down: {levels:?}"
    );
    // Dark at rest: from the line's last step (within a tick) through
    // the dwell after it.
    let stopped = steps.last().expect("steps") / 1000;
    for t in (stopped + 20_000..stopped + 450_000).step_by(10_000) {
        assert_eq!(report.recording.power_at(t), 0, "lit at rest at {t} µs");
    }
    // M3: S from start to end.
    let m3 = job("M3");
    let order: Vec<u16> = m3.recording.laser_power.iter().map(|l| l.1).collect();
    assert_eq!(order, [800, 0], "{:?}", m3.recording.laser_power);
}

#[test]
fn status_reads_home_while_dollar_h_homes_the_stepper() {
    let report = run_with_pan_switch(
        "@type-ahead $H\nwait 500\n@realtime 0x3f\nG4 P0.1\nwait 500\n@realtime 0x3f\n",
        30.0,
    );
    let (homed_at, _) = first_after(&report, "$H", |l| l.starts_with("[homed: stepper"));
    let during: Vec<_> = report
        .transcript
        .lines
        .iter()
        .filter(|(t, l)| l.starts_with('<') && *t < homed_at)
        .collect();
    assert!(!during.is_empty(), "no status while homing");
    assert!(
        during.iter().all(|(_, l)| l.starts_with("<Home|")),
        "{during:?}"
    );
    let after = statuses(&report);
    assert!(
        after.last().is_some_and(|l| l.starts_with("<Idle|")),
        "{after:?}"
    );
}

#[test]
fn a_resume_while_a_hold_still_brakes_goes_on_once_at_rest_and_the_job_finishes() {
    // Issue 25 defect 3: `~` 5 ms after `!` left the job stuck in `Run`.
    let report =
        run("G0 X70 Y40\n@realtime !\nwait 5\n@realtime ~\nwait 3000\n?\nG0 X0 Y0\nwait 2000\n?\n");
    let reports = statuses(&report);
    let [first, last] = reports[..] else {
        panic!("two status reports: {reports:?}");
    };
    assert!(first.starts_with("<Idle|"), "{first}");
    assert!(dist(mpos(first), [70.0, 40.0]) < 0.01, "{first}");
    assert!(last.starts_with("<Idle|"), "{last}");
    assert!(dist(mpos(last), [0.0, 0.0]) < 0.01, "{last}");
    // The spot went there and came back.
    let reached = gimbal_spot_mm(&report)
        .iter()
        .any(|s| dist(s.1, [70.0, 40.0]) < 1.0);
    assert!(reached, "the spot never reached (70, 40)");
    assert!(dist(spot_mm_at(&report, report.end_time_us), [0.0, 0.0]) < 0.5);
}

#[test]
fn the_first_g1_after_power_up_a_reset_or_target_stepper_is_lit_at_its_feed() {
    // Issue 25 defect 4: it ran dark at rapid speed (20 mm in ~130 ms).
    let cases = [
        ("power-up", "", [0.0, 20.0]),
        (
            "soft reset",
            "G0 X-10\nwait 1000\n@realtime 0x18\nwait 100\n$X\n",
            [-10.0, 10.0],
        ),
        (
            "target stepper",
            "G0 X-10\nwait 1000\ntarget stepper\nwait 100\n",
            [-10.0, 10.0],
        ),
    ];
    for (case, before, [x0, x1]) in cases {
        let report = run(&format!("{before}M3 S1000\nG1 X{x1} F600\nwait 3000\n"));
        let from_us = sent_at(&report, &format!("G1 X{x1} F600"));
        let lit: Vec<(u64, [f64; 2])> = gimbal_spot_mm(&report)
            .into_iter()
            .filter(|s| s.2 && s.0 > from_us)
            .map(|s| (s.0, s.1))
            .collect();
        assert!(lit.len() > 10, "{case}: lit {} samples", lit.len());
        let lit_s = (lit[lit.len() - 1].0 - lit[0].0) as f64 / 1e6;
        // 20 mm at 10 mm/s: 2 s (the ramps add a little).
        assert!((1.9..2.2).contains(&lit_s), "{case}: lit for {lit_s} s");
        for (t, p) in &lit {
            // On the programmed line (a step's rounding off it).
            let on = p[1].abs() < 0.6 && p[0] > x0 - 0.6 && p[0] < x1 + 0.6;
            assert!(on, "{case}: lit at {p:?} at {t} µs, off the line");
        }
        let end = spot_mm_at(&report, report.end_time_us);
        assert!(dist(end, [x1, 0.0]) < 0.6, "{case}: ended at {end:?}");
    }
}

#[test]
fn a_line_typed_ahead_of_target_stepper_runs_to_its_end() {
    // The stop of `target stepper` came to rest after the line's move
    // was sent; its report used to drop the move (stuck in `Run`).
    let report = run(
        "G0 X10\nwait 1000\n@type-ahead target stepper\n@type-ahead G1 X20 F600\nwait 3000\n?\n",
    );
    let status = statuses(&report).pop().expect("a status report");
    assert!(status.starts_with("<Idle|"), "{status}");
    assert!(dist(mpos(status), [20.0, 0.0]) < 0.01, "{status}");
}

#[test]
fn a_line_from_axes_beyond_their_soft_limits_is_refused_with_alarm_2_dark() {
    // Pan at 13.5°, then its limit set to 10°: no board line
    // starts there; the job ends in a soft-limit alarm, nothing lit moves.
    let report =
        run("G0 X-60\nwait 1000\nset stepper.pan.max_deg 10\nM3 S1000\nG1 X0 F600\nwait 2000\n?\n");
    let lines = terminal_lines(&report);
    assert!(
        lines.contains(&"[MSG:stepper: move refused: Unreachable]") && lines.contains(&"ALARM:2"),
        "{lines:?}"
    );
    let status = statuses(&report).pop().expect("a status report");
    assert!(status.starts_with("<Alarm|"), "{status}");
    let g1_us = sent_at(&report, "G1 X0 F600");
    let moved_lit = gimbal_spot_mm(&report)
        .iter()
        .filter(|s| s.2 && s.0 >= g1_us)
        .any(|s| dist(s.1, [-60.0, 0.0]) > 0.5);
    assert!(!moved_lit, "lit off the start");
    assert!(dist(spot_mm_at(&report, report.end_time_us), [-60.0, 0.0]) < 0.5);
}
