//! `cargo xtask calib camera --port DEVICE --camera DEVICE|sim`: the
//! calibration with the board attached. The board is driven with the
//! product's own console commands (`goto`, `laser`, `set`, `save`,
//! `status`); the camera sees a laser-off frame (the board located by
//! its markers) and then the spot at every grid point; the error model is
//! fitted as offline. With `--apply` the `set err.*` lines and `save`
//! go to the board and the grid is measured again (the verification
//! pass). Without it the board's own model is put back.
//!
//! The model is zeroed while measuring (the errors are those of the bare
//! build); anything refused puts the board's model back, stops it dark,
//! and writes nothing.

mod board;

use std::path::Path;
use std::time::Duration;

use camera_calib::markers::MarkerDetector;
use camera_calib::measure::{BoardView, locate_board};
use camera_calib::target::TargetLayout;
use kinematics_core::MeasuredPoint;

use super::camera::{CameraRunArgs, ErrorStats, Fitted, measured_point, write_outputs};
use super::capture::{self, FrameSource};
use board::Board;

/// Exposures averaged for the laser-off frame.
const BACKGROUND_FRAMES: usize = 8;

/// The commanded points: every `every`th grid point of the target, mm.
fn commanded(layout: &TargetLayout, every: usize) -> Vec<[f64; 2]> {
    layout
        .grid_points_mm()
        .into_iter()
        .step_by(every.max(1))
        .collect()
}

/// Measures the spot at every point of `points` (the laser-off frame
/// `background`, the board located as `view`).
fn measure_pass(
    board: &mut Board,
    camera: &mut dyn FrameSource,
    view: &BoardView,
    background: &camera_calib::image::GrayImage,
    points: &[[f64; 2]],
    a: &CameraRunArgs,
) -> Result<(Vec<MeasuredPoint>, f64), String> {
    let mut measured = Vec::with_capacity(points.len());
    let mut sigma_max = 0.0f64;
    for (k, p) in points.iter().enumerate() {
        let name = format!(
            "point {} of {} ({:.2}, {:.2}) mm",
            k + 1,
            points.len(),
            p[0],
            p[1]
        );
        board.aim(*p).map_err(|e| format!("{name}: {e}"))?;
        std::thread::sleep(Duration::from_millis(a.settle_ms));
        let frame = camera
            .capture(a.frames_per_point)
            .map_err(|e| format!("{name}: {e}"))?;
        let spot = view
            .measure(background, &frame)
            .map_err(|e| format!("{name}: {e}"))?;
        sigma_max = sigma_max.max(spot.sigma_mm);
        measured.push(measured_point(*p, spot.board_mm));
    }
    board.dark()?;
    Ok((measured, sigma_max))
}

/// The laser-off frame and the board located in it.
fn locate(
    board: &mut Board,
    camera: &mut dyn FrameSource,
    layout: &TargetLayout,
    a: &CameraRunArgs,
) -> Result<(camera_calib::image::GrayImage, BoardView), String> {
    board.dark()?;
    std::thread::sleep(Duration::from_millis(a.settle_ms));
    let background = camera
        .capture(BACKGROUND_FRAMES)
        .map_err(|e| format!("laser-off frame: {e}"))?;
    let intrinsics =
        super::intrinsics::load(a.intrinsics.as_deref(), background.width, background.height)?;
    let mut detector = MarkerDetector::new(background.width, background.height)?;
    let view = locate_board(&mut detector, &background, layout, intrinsics)
        .map_err(|e| format!("laser-off frame: {e}"))?;
    Ok((background, view))
}

/// Runs the online calibration against the board at `port`.
pub(super) fn online_command(a: &CameraRunArgs, port: &Path) -> Result<String, String> {
    if a.every == 0 || a.frames_per_point == 0 {
        return Err("--every and --frames-per-point must be at least 1".into());
    }
    let camera_name = a
        .camera
        .as_deref()
        .ok_or("--port needs --camera DEVICE|sim")?;
    let layout = super::camera::layout(a.pitch_mm, 6, 4)?;
    let points = commanded(&layout, a.every);
    let mut camera = capture::open(
        camera_name,
        port,
        a.spot_feed.as_deref(),
        &layout,
        a.sim_distortion_percent,
    )?;
    let mut board = Board::open(port)?;
    let saved_model = board.prepare()?;
    let result = calibrate(&mut board, camera.as_mut(), &layout, &points, a, port);
    let _ = board.dark();
    if !board.model_sent {
        // Refused, failed or not asked to apply: the board's own model back.
        board
            .set_model(&saved_model)
            .map_err(|e| format!("putting the board's error model back: {e}"))?;
    }
    let mut report = result.map_err(|e| match board.model_sent {
        true => format!("{e} (the new model was sent and saved before this)"),
        false => e,
    })?;
    report.port = Some(port.display().to_string());
    report.camera = Some(camera_name.to_owned());
    serde_json::to_string(&report).map_err(|e| e.to_string())
}

fn calibrate(
    board: &mut Board,
    camera: &mut dyn FrameSource,
    layout: &TargetLayout,
    points: &[[f64; 2]],
    a: &CameraRunArgs,
    port: &Path,
) -> Result<super::camera::CameraReport, String> {
    let (background, view) = locate(board, camera, layout, a)?;
    let (measured, sigma) = measure_pass(board, camera, &view, &background, points, a)?;
    let fitted = Fitted::new(measured, port)?;
    let mut after_measured = None;
    if a.apply {
        board.send_model(&fitted.firmware)?;
        let (after, _) = measure_pass(board, camera, &view, &background, points, a)?;
        after_measured = Some(after);
    }
    let after_vectors: Vec<(f64, f64)> = match &after_measured {
        Some(after) => after.iter().map(|p| (p.dx_mm, p.dy_mm)).collect(),
        None => fitted.after.clone(),
    };
    let mut report = fitted.report(
        &view,
        sigma,
        after_measured
            .as_ref()
            .map(|after| ErrorStats::of(after.iter().map(|p| (p.dx_mm, p.dy_mm)))),
    );
    report.applied = Some(a.apply);
    let json = serde_json::to_string(&report).map_err(|e| e.to_string())?;
    write_outputs(a, &fitted, &after_vectors, &json)?;
    Ok(report)
}

#[cfg(test)]
mod tests;
