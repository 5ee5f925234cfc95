//! The calibration flow of the README, end to end in the simulator: an
//! imperfect build (board rolled, yaw servo mounted off zero) is measured
//! on the grid, the quadratic error model is fitted with `kinematics-core`
//! (as `cargo xtask calib fit` does), loaded with `set err.*` lines, and
//! the same pattern then lands much closer to the grid points.

use kinematics_core::{MeasuredPoint, fit};
use laser_sim::bench::BenchBuild;
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{assert_calibration_build_safety, run_with};

/// The build error of the README's calibration figures, as
/// `cargo xtask sim --board-roll-deg 1 --yaw-zero-deg 0.8` sets it.
fn imperfect_build() -> BenchBuild {
    BenchBuild {
        board_roll_deg: 1.0,
        yaw_zero_deg: 0.8,
        ..BenchBuild::default()
    }
}

fn run_grid(setup: &str) -> SimReport {
    let report = run_with(
        &format!("{setup}set dwell_ms 50\npattern grid-full serpentine once\n"),
        imperfect_build()
            .apply(SimOptions::default())
            .expect("a valid build error"),
    );
    // Uncalibrated (no `set err.*`), the build puts the spot several mm
    // off its grid and the safety checker's figure rule says so;
    // calibrated, it holds with the rest.
    assert_calibration_build_safety(&report, !setup.is_empty());
    assert!(report.succeeded(false), "{:?}", report.transcript);
    assert_eq!(report.recording.dwells.len(), 13 * 9);
    report
}

/// (target, measured error) of every dwell, mm.
fn measurements(report: &SimReport) -> Vec<MeasuredPoint> {
    report
        .recording
        .dwells
        .iter()
        .map(|d| {
            let ([x_mm, y_mm], [dx_mm, dy_mm]) = (d.target_mm(), d.error_mm());
            MeasuredPoint {
                x_mm,
                y_mm,
                dx_mm,
                dy_mm,
            }
        })
        .collect()
}

fn max_error_mm(points: &[MeasuredPoint]) -> f64 {
    points
        .iter()
        .map(|p| p.dx_mm.hypot(p.dy_mm))
        .fold(0.0, f64::max)
}

#[test]
fn a_fitted_error_model_compensates_an_imperfect_build() {
    let before = measurements(&run_grid(""));
    let before_max = max_error_mm(&before);
    assert!(
        before_max > 5.0,
        "the build is visibly off: {before_max:.2} mm"
    );

    let report = fit(&before).expect("117 grid points determine the model");
    let model = report.model();
    let mut setup = String::new();
    for (axis, q) in [("dx", model.dx), ("dy", model.dy)] {
        for (i, c) in q.coef.iter().enumerate() {
            setup.push_str(&format!("set err.{axis}.c{i} {c}\n"));
        }
    }
    let after = measurements(&run_grid(&setup));
    let after_max = max_error_mm(&after);
    eprintln!("calibration: max error {before_max:.2} mm before, {after_max:.2} mm after");
    // What remains is the quadratic model's residual plus 0.1° servo
    // resolution (~0.3 mm here).
    assert!(
        after_max < 0.1 * before_max && after_max < 0.8,
        "max error {before_max:.2} mm before, {after_max:.2} mm after"
    );
}
