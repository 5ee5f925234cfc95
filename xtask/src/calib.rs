//! `cargo xtask calib …`: error-model fitting (SPEC §5).
//!
//! `calib fit --input FILE.csv [--output FILE]` reads measured points (CSV
//! header exactly `x,y,dx,dy`, all mm: commanded position and the error
//! spot − commanded), fits the quadratic of each axis and prints one JSON
//! object `{"dx":{"coef":[c0..c5],"sse":…,"r2":…,"rmse":…,"n":…},"dy":{…}}`
//! (coefficients for 1, x, y, x², xy, y²; `rmse` is null for exactly 6
//! points). `sse`, `r2` and `rmse` are those of the printed coefficients
//! evaluated as the firmware evaluates them. Every value must be finite
//! and within ±10 m (10000 mm). Errors print `{"error":"…"}` (naming the CSV line) and exit 1.
//!
//! `--output FILE` writes the model as firmware command lines: `#` comment
//! lines, then `set err.dx.c0 <mm>` … `set err.dy.c5 <mm>` at full
//! precision. Paste it into the USB command line (or run it with
//! `cargo xtask sim --script FILE`), then `save`.

use std::fs::File;
use std::path::PathBuf;
use std::process::ExitCode;

use kinematics_core::{FitReport, fit};
use serde::Serialize;

use crate::json_out::emit;
use output::{AxisOut, firmware_commands};
use xtask::calib_csv::read_points;

/// `cargo xtask calib …`
#[derive(clap::Args, Debug)]
pub struct CalibArgs {
    #[command(subcommand)]
    command: CalibCommand,
}

#[derive(clap::Subcommand, Debug)]
enum CalibCommand {
    /// Fit the error model to measured points; prints JSON.
    Fit(FitArgs),
    /// Write the printable camera target (SVG or PDF, print at 100 %).
    Target(camera::TargetArgs),
    /// Measure the spot with a camera (offline frames, or online driving
    /// the board) and fit the error model; `calib camera intrinsics`: the lens.
    Camera(Box<CameraArgs>),
    /// Render the simulator's grid run as virtual-camera frames.
    Frames(frames::FramesArgs),
}

#[derive(clap::Args, Debug)]
struct FitArgs {
    /// Measured points: CSV with header `x,y,dx,dy` (mm).
    #[arg(long)]
    input: PathBuf,
    /// Also write the model as firmware `set err.*` command lines here.
    #[arg(long)]
    output: Option<PathBuf>,
}

#[derive(Serialize)]
struct FitOut {
    dx: AxisOut,
    dy: AxisOut,
}

/// Runs `calib …`.
pub fn run(args: CalibArgs) -> anyhow::Result<ExitCode> {
    Ok(emit(match args.command {
        CalibCommand::Fit(a) => fit_command(&a),
        CalibCommand::Target(a) => camera::target_command(&a),
        CalibCommand::Camera(a) => camera_command(&a),
        CalibCommand::Frames(a) => frames::frames_command(&a),
    }))
}

fn fit_command(a: &FitArgs) -> Result<String, String> {
    let file =
        File::open(&a.input).map_err(|e| format!("cannot read {}: {e}", a.input.display()))?;
    let points = read_points(file).map_err(|e| format!("{}: {e}", a.input.display()))?;
    let report = fit(&points).map_err(|e| format!("fit failed: {e}"))?;
    if let Some(out) = &a.output {
        let text = firmware_commands(&report, &a.input)?;
        std::fs::write(out, text).map_err(|e| format!("cannot write {}: {e}", out.display()))?;
    }
    fit_json(&report)
}

fn fit_json(report: &FitReport) -> Result<String, String> {
    serde_json::to_string(&FitOut {
        dx: (&report.dx).into(),
        dy: (&report.dy).into(),
    })
    .map_err(|e| e.to_string())
}

pub(crate) mod camera;
mod capture;
mod frame_source;
pub(super) mod frames;
mod intrinsics;
mod online;
mod output;
mod picture;
#[cfg(feature = "webcam")]
mod webcam;

#[cfg(test)]
mod tests;

/// `calib camera`: offline (`--images DIR --points CSV`), online
/// (`--port DEVICE --camera DEVICE|sim`), or `calib camera intrinsics`.
#[derive(clap::Args, Debug)]
#[command(args_conflicts_with_subcommands = true)]
pub struct CameraArgs {
    #[command(subcommand)]
    sub: Option<CameraSub>,
    #[command(flatten)]
    run: camera::CameraRunArgs,
}

#[derive(clap::Subcommand, Debug)]
enum CameraSub {
    /// The camera's intrinsics and radial distortion from several views of
    /// the target (Zhang's method), for `calib camera --intrinsics FILE`.
    Intrinsics(intrinsics::IntrinsicsArgs),
}

/// `calib camera`: `intrinsics`, or a calibration run offline or online.
fn camera_command(a: &CameraArgs) -> Result<String, String> {
    match (&a.sub, &a.run) {
        (Some(CameraSub::Intrinsics(i)), _) => intrinsics::intrinsics_command(i),
        (None, run) => run_command(run),
    }
}

/// `calib camera` offline or online, as the arguments say.
pub(crate) fn run_command(a: &camera::CameraRunArgs) -> Result<String, String> {
    match (&a.port, &a.images, &a.points) {
        (Some(port), _, _) => online::online_command(a, port),
        (None, Some(images), Some(points)) => camera::offline_command(a, images, points),
        _ => Err("give --images DIR --points CSV (offline) or --port DEVICE --camera DEVICE|sim (online)".into()),
    }
}
