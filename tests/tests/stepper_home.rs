//! Homing and limit switches on the stepper pan/tilt in the simulator: a
//! switch model on the simulated axis (closes at a true joint angle, with
//! hysteresis), `home` from several power-up positions, a switch that
//! never closes, no switches, and a switch hit during a move.

use kinematics_core::gimbal::JointAngles;
use laser_sim::stepper::{LimitSwitch, StepPin, StepperGeometry};
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{gimbal_dark_after, run_with, terminal_lines};

/// The seed's step: 1.8° / 32.
const DEG_PER_STEP: f64 = 0.05625;

/// A run with a pan switch closing at `switch_deg` (towards positive
/// angles), the pan axis powered up at `start_deg` (true joint angle).
fn run_pan(script: &str, start_deg: f64, switch_deg: f64) -> SimReport {
    run_pan_switch(script, start_deg, switch_deg, true)
}

/// As [`run_pan`], the switch towards positive or negative angles.
fn run_pan_switch(script: &str, start_deg: f64, switch_deg: f64, positive: bool) -> SimReport {
    run_with(
        script,
        SimOptions {
            stepper_geometry: StepperGeometry {
                zero: JointAngles {
                    yaw_deg: start_deg,
                    pitch_deg: 0.0,
                },
                ..StepperGeometry::default()
            },
            stepper_switches: [
                Some(LimitSwitch {
                    closes_at_deg: switch_deg,
                    towards_positive: positive,
                    hysteresis_deg: 0.4,
                }),
                None,
            ],
            ..SimOptions::default()
        },
    )
}

/// The line (or bracketed notice) starting with `prefix`.
fn line<'a>(report: &'a SimReport, prefix: &str) -> &'a str {
    terminal_lines(report)
        .into_iter()
        .find(|l| l.trim_start_matches('[').starts_with(prefix))
        .unwrap_or_else(|| panic!("no {prefix:?} line: {:?}", terminal_lines(report)))
}

const HOME_PAN: &str =
    "set stepper.pan.home_dir 1\nset stepper.pan.home_deg 30\ntarget stepper\nhome\nwait 9000\n";

#[test]
fn homing_finds_the_switch_within_one_microstep_from_several_start_positions() {
    for start_deg in [-40.0, 7.3, 29.0] {
        // After homing, `goto 0 0` aims at step 0 of the homed zero: the
        // true pan angle there is the zero's error.
        let report = run_pan(&format!("{HOME_PAN}goto 0 0\nwait 2000\n"), start_deg, 30.0);
        line(&report, "homed: stepper at pan 28.0");
        let counted = report.stepper.axes[0].counted_steps();
        let true_deg = start_deg + counted as f64 * DEG_PER_STEP;
        assert!(
            true_deg.abs() <= DEG_PER_STEP + 1e-9,
            "start {start_deg}: step 0 is at {true_deg}°"
        );
        assert!(!report.stepper.stalled(), "{}", report.stepper.report());
    }
}

#[test]
fn homing_reports_a_switch_that_never_closes_within_the_travel() {
    // The switch is beyond the travel (soft-limit span 120° + 2 × 2°).
    let report = run_pan(HOME_PAN, 0.0, 170.0);
    line(
        &report,
        "error: home failed: pan switch not found within the travel; not homed",
    );
    let farthest = pan_extreme_steps(&report) as f64 * DEG_PER_STEP;
    assert!((farthest - 124.0).abs() < 0.1, "seeked {farthest}°");
    // Then back to where the seek began: the position stays known.
    assert_eq!(report.stepper.axes[0].counted_steps(), 0);
}

/// The pan step position farthest from power-up during the run, steps
/// (from the STEP and DIR edges; DIR high is negative).
fn pan_extreme_steps(report: &SimReport) -> i64 {
    let (mut at, mut negative, mut farthest) = (0_i64, false, 0_i64);
    for e in report.stepper.edges.iter().filter(|e| e.axis == 0) {
        match e.pin {
            StepPin::Dir => negative = e.high,
            StepPin::Step if e.high => {
                at += if negative { -1 } else { 1 };
                if at.abs() > farthest.abs() {
                    farthest = at;
                }
            }
            _ => {}
        }
    }
    farthest
}

#[test]
fn failed_homing_repeated_leaves_the_axis_where_it_was_and_status_says_homing() {
    // Issue 25 defect 6: each failed `$H` wound pan another 124° while
    // `?` said MPos:0,0; `status` said idle while it sought.
    let script = "set stepper.pan.home_dir 1\nset stepper.pan.home_deg 30\ntarget stepper\n\
                  home\nwait 500\nstatus\nwait 20000\n$H\n$H\n$H\n?\n$X\nG0 X0 Y0\nwait 2000\n?\n";
    let report = run_pan(script, 0.0, 170.0);
    line(&report, "state: homing");
    let lines = terminal_lines(&report);
    let alarms = lines.iter().filter(|l| **l == "ALARM:9").count();
    assert_eq!(alarms, 3, "{lines:?}");
    assert_eq!(report.stepper.axes[0].counted_steps(), 0);
    let statuses: Vec<&str> = lines.into_iter().filter(|l| l.starts_with('<')).collect();
    for status in &statuses {
        assert!(status.contains("|MPos:0.000,0.000,"), "{status}");
    }
    assert!(statuses.last().is_some_and(|s| s.starts_with("<Idle|")));
    let spot = report.recording.spot.last().expect("spot samples");
    assert!(spot.x_cm.hypot(spot.y_cm) < 0.05, "spot at {spot:?}");
}

#[test]
fn home_without_switches_says_so_and_the_position_stays_zero() {
    let report = run_pan("target stepper\nhome\ngoto 0 0\nwait 500\n", 0.0, 170.0);
    line(&report, "error: home: no homing switches configured");
    assert_eq!(report.stepper.axes[0].counted_steps(), 0);
}

#[test]
fn a_switch_hit_during_a_move_halts_the_steps_with_the_laser_dark() {
    // The line from (−14, 0) to (14, 0), lit, turns pan from +29.2° to
    // −29.2°: through the switch closing at −10°.
    let report = run_pan_switch(
        "target stepper\npattern line -14 0 14 0 once\nwait 3000\n",
        0.0,
        -10.0,
        false,
    );
    line(
        &report,
        "error: stepper limit switch pan hit: steps halted, laser off",
    );
    let counted = report.stepper.axes[0].counted_steps();
    // Halted at the first step inside the switch (−10° = −177.8 steps).
    assert_eq!(counted, -178);
    let last_step_ns = report
        .stepper
        .edges
        .iter()
        .filter(|e| e.axis == 0 && e.pin == StepPin::Step && e.high)
        .map(|e| e.t_ns)
        .max()
        .expect("it stepped");
    let lit = |t_us: u64| {
        let events = &report.recording.laser_events;
        events
            .iter()
            .rev()
            .find(|(t, _)| *t <= t_us)
            .is_some_and(|(_, on)| *on)
    };
    assert!(lit(last_step_ns / 1000), "it was drawing, lit, when it hit");
    assert!(
        gimbal_dark_after(&report, last_step_ns / 1000) <= 1_000,
        "laser dark within 1 ms of the hit"
    );
}
