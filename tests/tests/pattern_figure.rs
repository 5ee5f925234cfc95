//! Rule (h) of the safety checker, `off-figure` (issue 25): every lit
//! sample of a `pattern`, `goto` or `grid` run lies within the spot's
//! tolerance of the figure modelled from the transcript. Real runs of
//! every pattern on every actuator keep to their figures; the same
//! recordings, falsified (a circle drawn 5 mm to the side, a travel
//! between grid points lit in `laser dwell`, a galvo whose board is 1 %
//! farther than it thinks), fail with `off-figure`.

use laser_sim::physics::PhysicalGalvo;
use laser_sim::safety::{SafetyInputs, ViolationKind, check, check_inputs, report_text};
use laser_sim::script::DEMO_SCRIPT;
use laser_sim::servo_port::{BusFaults, SilentWindow};
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{UNTIL_STEP_FIXES, assert_safe_allowing, run_to_idle, run_with};

/// Whether `inputs` break the figure rule.
fn off_figure(inputs: &SafetyInputs<'_>) -> bool {
    check_inputs(inputs)
        .iter()
        .any(|v| v.kind == ViolationKind::OffFigure)
}

/// Shows the figure rule judged `report`'s runs: moved by half a grid
/// pitch on both axes (off every grid point, row, column and the drawn
/// paths), the gimbal's or stepper's spot is off its figure; with a
/// galvo whose board is 5 % farther than it thinks, so is the galvo's.
fn judged(report: &SimReport, script: &str, pointing: bool, galvo: bool) {
    if pointing {
        let mut moved = report.recording.spot.clone();
        for s in &mut moved {
            s.x_cm += 0.958;
            s.y_cm -= 0.958;
        }
        let inputs = SafetyInputs {
            spot: &moved,
            ..SafetyInputs::from_report(report)
        };
        assert!(off_figure(&inputs), "{script:?}: the moved spot passes");
    }
    if galvo {
        let mut inputs = SafetyInputs::from_report(report);
        inputs.galvo_physics.galvo.geometry.d_mm *= 1.05;
        assert!(off_figure(&inputs), "{script:?}: the far galvo passes");
    }
}

/// Runs `script`, checks every invariant and that the spot was lit (so
/// the figure rule had something to judge); returns the report.
fn run_safe(script: &str, galvo: bool) -> SimReport {
    let report = run_to_idle(script);
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
    let lit = if galvo {
        report.dac.runs().any(|r| r.3.laser)
    } else {
        report.recording.spot.iter().any(|s| s.laser)
    };
    assert!(lit, "{script:?}: never lit");
    report
}

/// The kinds of the breaches of `report`.
fn kinds(report: &SimReport) -> Vec<ViolationKind> {
    check(report).iter().map(|v| v.kind).collect()
}

#[test]
fn the_demo_and_every_pattern_keep_to_their_figures() {
    // (script, the gimbal or stepper judged, the galvo judged)
    let scripts = [
        (DEMO_SCRIPT, true, true),
        ("set dwell_ms 50\npattern visit-all once\n", true, false),
        (
            "laser dwell\nset dwell_ms 50\npattern horizontal once\n",
            true,
            false,
        ),
        (
            "set grid.pitch_cm 2\nset grid.x_offset_cm 0.5\nset dwell_ms 50\npattern vertical once\n",
            true,
            false,
        ),
        (
            "pattern line -3 -2 4 3 once\nwait 3000\npattern rect -2 -1 3 2 once\nwait 4000\n\
             pattern tuning 1 0 4 once\nwait 6000\n",
            true,
            false,
        ),
        (
            "goto 5 -3\nwait 600\ngrid 2 1\nwait 600\nstop\n",
            true,
            false,
        ),
        (
            "target stepper\nset dwell_ms 50\npattern corner once\nwait 3000\n\
             pattern circle 1 1 3 cw once\nwait 3000\n",
            true,
            false,
        ),
        (
            "target galvo\nset dwell_ms 50\npattern grid-full once\nwait 8000\n\
             pattern circle 1 1 3 once\nwait 500\npattern rect -4 -3 2 5 once\nwait 500\n",
            false,
            true,
        ),
        (
            "target both\nset dwell_ms 50\npattern corner once\n",
            true,
            true,
        ),
    ];
    for (script, pointing, galvo) in scripts {
        let report = run_safe(script, galvo && !pointing);
        judged(&report, script, pointing, galvo);
    }
}

/// The shared scenarios (`tests/scenarios/`) that draw, run in the
/// simulator as `xtask scenario` runs them there.
#[test]
fn the_shared_scenarios_keep_to_their_figures() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    // (scenario, the gimbal judged, the galvo judged)
    for (name, pointing, galvo) in [
        ("grid", true, false),
        ("switch", true, false),
        ("galvo_tuning", false, true),
        ("interlock", true, false),
        ("silent_servo", true, false),
    ] {
        let script = std::fs::read_to_string(root.join(format!("{name}.txt")))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let faults = if name == "silent_servo" {
            // `#! fault servo-silent:1@2500`
            BusFaults {
                silent: vec![SilentWindow {
                    id: 1,
                    from_ms: 2500,
                    until_ms: None,
                }],
                ..BusFaults::default()
            }
        } else {
            BusFaults::default()
        };
        assert!(name != "silent_servo" || script.contains("servo-silent:1@2500"));
        let report = run_with(
            &script,
            SimOptions {
                faults,
                ..SimOptions::default()
            },
        );
        assert_safe_allowing(&report, UNTIL_STEP_FIXES);
        judged(&report, name, pointing, galvo);
    }
}

#[test]
fn a_circle_drawn_beside_its_figure_is_off_it() {
    let mut report = run_safe("pattern circle 2 1 4 ccw once\nwait 2500\n", false);
    // 5 mm to the right: beyond the gimbal's 2 mm and half a 2 mm step.
    for s in &mut report.recording.spot {
        s.x_cm += 0.5;
    }
    let found = check(&report);
    assert!(
        found.iter().any(|v| v.kind == ViolationKind::OffFigure),
        "{}",
        report_text(&found)
    );
}

#[test]
fn a_lit_travel_between_grid_points_in_dwell_mode_is_off_the_figure() {
    let mut report = run_safe(
        "laser dwell\nset dwell_ms 200\npattern corner once\n",
        false,
    );
    assert!(!kinds(&report).contains(&ViolationKind::OffFigure));
    // Light every sample: the travels between the corners too.
    for s in &mut report.recording.spot {
        s.laser = true;
    }
    let found = check(&report);
    let off: Vec<_> = found
        .iter()
        .filter(|v| v.kind == ViolationKind::OffFigure)
        .collect();
    assert!(!off.is_empty(), "{}", report_text(&found));
    assert!(off[0].detail.contains("pattern corner once"), "{off:?}");
}

#[test]
fn a_galvo_that_misplaces_its_figure_is_off_it() {
    let report = run_safe("target galvo\npattern tuning 0 0 8 once\nwait 1500\n", true);
    let mut inputs = SafetyInputs::from_report(&report);
    // The board 1 % farther than the firmware thinks: the 80 mm square's
    // corners land ~0.6 mm out, twice the galvo's 0.3 mm.
    let mut far = PhysicalGalvo::default();
    far.galvo.geometry.d_mm *= 1.01;
    inputs.galvo_physics = far;
    let found = check_inputs(&inputs);
    assert!(
        found.iter().any(|v| v.kind == ViolationKind::OffFigure),
        "{}",
        report_text(&found)
    );
}
