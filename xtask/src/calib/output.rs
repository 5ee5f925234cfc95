//! A fitted model as output: the JSON of one axis and the firmware
//! command lines (see [`super`]).

use std::fmt::Write as _;
use std::path::Path;

use kinematics_core::error_model::COEF_LIMITS;
use kinematics_core::{AxisFit, FitReport};
use serde::Serialize;

/// Longest line the firmware's command line accepts, bytes.
pub(super) const FIRMWARE_MAX_LINE: usize = 128;

#[derive(Serialize)]
pub(super) struct AxisOut {
    coef: [f64; 6],
    sse: f64,
    r2: f64,
    rmse: Option<f64>,
    n: usize,
}

impl From<&AxisFit> for AxisOut {
    fn from(f: &AxisFit) -> Self {
        Self {
            coef: f.coef,
            sse: f.sse,
            r2: f.r2,
            rmse: f.rmse,
            n: f.n,
        }
    }
}

/// A value in the shortest form that parses back to exactly `v`, short
/// enough for a firmware command line.
pub(super) fn exact_number(v: f64) -> String {
    let plain = format!("{v}");
    if plain.len() <= 24 {
        plain
    } else {
        format!("{v:e}")
    }
}

/// Printable ASCII only (the firmware rejects other bytes), at most
/// `FIRMWARE_MAX_LINE` bytes.
pub(super) fn comment_line(text: &str) -> String {
    let mut line: String = format!("# {text}")
        .chars()
        .map(|c| {
            if c == ' ' || c.is_ascii_graphic() {
                c
            } else {
                '?'
            }
        })
        .collect();
    line.truncate(FIRMWARE_MAX_LINE);
    line
}

/// The model as firmware command lines (see the module docs).
pub(crate) fn firmware_commands(report: &FitReport, source: &Path) -> Result<String, String> {
    let mut out = String::new();
    let comments = [
        "Error model for the laser pointing controller (SPEC 5), written by".to_owned(),
        format!(
            "`cargo xtask calib fit` from {} ({} points).",
            source.display(),
            report.dx.n
        ),
        "err.<axis>.c0..c5: d = c0 + c1*x + c2*y + c3*x^2 + c4*x*y + c5*y^2 (x, y, d in mm)."
            .into(),
        axis_summary("dx", &report.dx),
        axis_summary("dy", &report.dy),
        "Paste into the USB command line (or `cargo xtask sim --script FILE`), then `save`.".into(),
    ];
    for c in comments {
        let _ = writeln!(out, "{}", comment_line(&c));
    }
    for (axis, f) in [("dx", &report.dx), ("dy", &report.dy)] {
        for ((i, c), limit) in f.coef.iter().enumerate().zip(COEF_LIMITS) {
            if c.abs() > limit {
                return Err(format!(
                    "err.{axis}.c{i} = {c} is outside the firmware's range +-{limit}; \
                     check the units (mm) of the CSV"
                ));
            }
            let _ = writeln!(out, "set err.{axis}.c{i} {}", exact_number(*c));
        }
    }
    Ok(out)
}

fn axis_summary(axis: &str, f: &AxisFit) -> String {
    let rmse = f
        .rmse
        .map_or_else(|| "n/a (6 points)".into(), |r| format!("{r:.6} mm"));
    format!(
        "{axis}: SSE {:.6} mm^2, R^2 {:.6}, RMSE {rmse}",
        f.sse, f.r2
    )
}
