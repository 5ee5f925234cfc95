//! G-code on the stepper pan/tilt in the simulator (issues 12 and 13):
//! a soft reset halts the steps at once, a feed hold brakes at once from
//! the segment being executed, the feed override applies on the fly, the
//! laser power path, `$H` answered when homing ends, and `$11` saved.

use laser_sim::stepper::{StepEdge, StepPin};
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{gimbal_dark_after, run_with, terminal_lines};

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
