//! The SSE `cargo xtask calib fit` reports is the SSE of the model the
//! firmware ends up holding: coefficients printed in their shortest exact
//! form, parsed by the firmware's command line, stored by `set err.*`, and
//! evaluated by the firmware's error model.

use kinematics_core::{PointMm, fit};
use laser_app::cli::parse::parse_line;
use laser_app::command::Command;
use laser_app::settings::Settings;

#[path = "../../kinematics-core/tests/support/mod.rs"]
mod support;
use support::noisy_grid;

#[test]
fn reported_sse_is_that_of_the_model_the_firmware_holds() {
    let points = noisy_grid();
    let report = fit(&points).unwrap();
    let mut settings = Settings::default();
    for (axis, f) in [("dx", &report.dx), ("dy", &report.dy)] {
        for (i, c) in f.coef.iter().enumerate() {
            // As `calib fit --output` writes it (shortest exact form,
            // in exponent notation when that is shorter than 25 bytes).
            let plain = format!("{c}");
            let number = if plain.len() <= 24 {
                plain
            } else {
                format!("{c:e}")
            };
            let line = format!("set err.{axis}.c{i} {number}");
            let Ok(Some(Command::Set { param, value })) = parse_line(&line) else {
                panic!("{line} does not parse");
            };
            assert_eq!(value, *c, "{line}: the firmware parses another number");
            settings.set(param, value).unwrap();
        }
    }
    let model = settings.error_model();
    let (mut sse_x, mut sse_y) = (0.0, 0.0);
    for p in &points {
        let e = model
            .error_at(PointMm {
                x_mm: p.x_mm,
                y_mm: p.y_mm,
            })
            .unwrap();
        sse_x += (p.dx_mm - e.x_mm) * (p.dx_mm - e.x_mm);
        sse_y += (p.dy_mm - e.y_mm) * (p.dy_mm - e.y_mm);
    }
    assert_eq!(report.dx.sse, sse_x);
    assert_eq!(report.dy.sse, sse_y);
}
