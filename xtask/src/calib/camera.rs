//! `cargo xtask calib target|camera|frames` (issue 22): the printable
//! target, the offline camera calibration (frames + commanded points →
//! `set err.*` lines, JSON report, SVG of the error vectors), and frames
//! of the simulator's virtual camera.

use std::path::{Path, PathBuf};

use camera_calib::measure::BoardView;
use camera_calib::offline::{MeasuredFrame, measure_frames, read_frame_list};
use camera_calib::target::{GridSpec, TargetLayout};
use kinematics_core::{FitReport, MeasuredPoint, PointMm, fit};
use serde::Serialize;

use super::output::{AxisOut, firmware_commands};

/// `calib target`
#[derive(clap::Args, Debug)]
pub struct TargetArgs {
    /// Where to write the board: `.svg`, or `.pdf` (page at the board's
    /// size; print at 100 %).
    #[arg(long)]
    pub(super) out: PathBuf,
    /// Grid pitch, mm (SPEC §4.1).
    #[arg(long, default_value_t = 19.16)]
    pub(super) pitch_mm: f64,
    /// Grid half-width in cells.
    #[arg(long, default_value_t = 6)]
    pub(super) xi_max: i32,
    /// Grid half-height in cells.
    #[arg(long, default_value_t = 4)]
    pub(super) yi_max: i32,
}

/// `calib camera` without a subcommand.
#[derive(clap::Args, Debug, Clone)]
pub struct CameraRunArgs {
    /// Offline: directory of the frames (PNG).
    #[arg(long, conflicts_with = "port")]
    pub images: Option<PathBuf>,
    /// Offline: frame list, CSV `image,x,y` (commanded board point of each frame, mm).
    #[arg(long, requires = "images")]
    pub points: Option<PathBuf>,
    /// Offline: laser-off frame of the same view (default: IMAGES/background.png).
    #[arg(long, requires = "images")]
    pub background: Option<PathBuf>,
    /// Online: the board's console (e.g. /dev/ttyACM0, or the simulator's PTY link).
    #[arg(long, requires = "camera")]
    pub port: Option<PathBuf>,
    /// Online: the camera, a V4L2 device (e.g. /dev/video0; needs the
    /// `webcam` feature) or `sim` (the simulator's virtual camera,
    /// rendering its spot feed).
    #[arg(long, requires = "port")]
    pub camera: Option<String>,
    /// Online, `--camera sim`: the simulator's spot feed (default: PORT.spot).
    #[arg(long)]
    pub spot_feed: Option<PathBuf>,
    /// Online, `--camera sim`: the virtual lens's radial distortion at the image corner, %.
    #[arg(long, default_value_t = 0.0)]
    pub sim_distortion_percent: f64,
    /// Online: send the fitted `set err.*` lines and `save` to the board,
    /// then measure the grid again (the verification pass).
    #[arg(long)]
    pub apply: bool,
    /// Online: measure every Nth grid point (1: all).
    #[arg(long, default_value_t = 1)]
    pub every: usize,
    /// Online: exposures averaged per point (8 for the laser-off frame).
    #[arg(long, default_value_t = 4)]
    pub frames_per_point: usize,
    /// Online: wait after the spot has arrived before capturing, ms.
    #[arg(long, default_value_t = 300)]
    pub settle_ms: u64,
    /// The camera's intrinsics (`calib camera intrinsics --out FILE`):
    /// pixels are undistorted before the homography.
    #[arg(long)]
    pub intrinsics: Option<PathBuf>,
    /// Write the model as firmware `set err.*` command lines here.
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// Write the JSON report here too (it is always printed).
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write an SVG of the error vectors (measured, and left after the fit) here.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Write the same picture as PNG here.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Grid pitch of the printed target, mm.
    #[arg(long, default_value_t = 19.16)]
    pub pitch_mm: f64,
}

impl CameraRunArgs {
    /// Offline arguments writing every output, for the tests.
    #[cfg(test)]
    pub(super) fn for_test(
        images: &Path,
        points: &Path,
        output: &Path,
        report: &Path,
        svg: &Path,
    ) -> Self {
        Self {
            images: Some(images.into()),
            points: Some(points.into()),
            background: None,
            port: None,
            camera: None,
            spot_feed: None,
            sim_distortion_percent: 0.0,
            apply: false,
            every: 1,
            frames_per_point: 4,
            settle_ms: 300,
            intrinsics: None,
            output: Some(output.into()),
            report: Some(report.into()),
            svg: Some(svg.into()),
            png: None,
            pitch_mm: 19.16,
        }
    }
}

/// Worst and RMS error of a point set, mm.
#[derive(Serialize, Debug, PartialEq)]
pub struct ErrorStats {
    /// Largest |error|, mm.
    pub worst_mm: f64,
    /// RMS |error|, mm.
    pub rms_mm: f64,
}

impl ErrorStats {
    pub(super) fn of(errors: impl Iterator<Item = (f64, f64)>) -> Self {
        let (mut worst, mut sum2, mut n) = (0.0f64, 0.0, 0.0);
        for (dx, dy) in errors {
            let e = dx.hypot(dy);
            worst = worst.max(e);
            sum2 += e * e;
            n += 1.0;
        }
        Self {
            worst_mm: worst,
            rms_mm: (sum2 / f64::max(n, 1.0)).sqrt(),
        }
    }
}

/// What a camera calibration measured and fitted (the JSON report).
#[derive(Serialize)]
pub(super) struct CameraReport {
    /// Online: the board's console.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub port: Option<String>,
    /// Online: the camera.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera: Option<String>,
    pub frames: usize,
    pub markers: Vec<u16>,
    pub reprojection_px: f64,
    pub intrinsics: bool,
    pub spot_sigma_mm_max: f64,
    pub before: ErrorStats,
    pub after_predicted: ErrorStats,
    /// Online with `--apply`: the verification pass.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub after: Option<ErrorStats>,
    /// Online: whether the model was sent and saved.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub applied: Option<bool>,
    pub dx: AxisOut,
    pub dy: AxisOut,
}

/// The error model fitted to camera measurements.
pub(super) struct Fitted {
    /// Commanded points and their measured errors.
    pub points: Vec<MeasuredPoint>,
    /// The fit.
    pub report: FitReport,
    /// Errors the model leaves at the same points, mm.
    pub after: Vec<(f64, f64)>,
    /// The model as firmware command lines.
    pub firmware: String,
}

impl Fitted {
    /// Fits `points` (measured through `source`); refused as the
    /// firmware would refuse it.
    pub fn new(points: Vec<MeasuredPoint>, source: &Path) -> Result<Self, String> {
        let report =
            fit(&points).map_err(|e| format!("fit refused ({} frames): {e}", points.len()))?;
        let after = residuals(&report, &points)?;
        let firmware = firmware_commands(&report, source)?;
        Ok(Self {
            points,
            report,
            after,
            firmware,
        })
    }

    /// The report's fields that come from the fit.
    pub fn report(
        &self,
        view: &BoardView,
        spot_sigma_mm_max: f64,
        after: Option<ErrorStats>,
    ) -> CameraReport {
        CameraReport {
            port: None,
            camera: None,
            frames: self.points.len(),
            markers: view.markers.clone(),
            reprojection_px: view.fit.rms_px,
            intrinsics: view.intrinsics.is_some(),
            spot_sigma_mm_max,
            before: ErrorStats::of(self.points.iter().map(|p| (p.dx_mm, p.dy_mm))),
            after_predicted: ErrorStats::of(self.after.iter().copied()),
            after,
            applied: None,
            dx: (&self.report.dx).into(),
            dy: (&self.report.dy).into(),
        }
    }
}

pub(super) fn layout(pitch_mm: f64, xi_max: i32, yi_max: i32) -> Result<TargetLayout, String> {
    TargetLayout::for_grid(GridSpec {
        pitch_mm,
        xi_max,
        yi_max,
    })
}

pub(super) fn target_command(a: &TargetArgs) -> Result<String, String> {
    let l = layout(a.pitch_mm, a.xi_max, a.yi_max)?;
    let is_pdf = a
        .out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("pdf"));
    let bytes = if is_pdf {
        camera_calib::print::pdf(&l)
    } else {
        l.svg().into_bytes()
    };
    std::fs::write(&a.out, bytes).map_err(|e| format!("cannot write {}: {e}", a.out.display()))?;
    let [x0, y0, x1, y1] = l.extent_mm;
    Ok(format!(
        "{{\"written\":{:?},\"width_mm\":{:.1},\"height_mm\":{:.1},\"tags\":{},\"tag_size_mm\":{:.2}}}",
        a.out.display().to_string(),
        x1 - x0,
        y1 - y0,
        l.tags.len(),
        l.tags.first().map_or(0.0, |t| t.size_mm)
    ))
}

/// The measured point of a spot measured at `spot_mm` for `commanded_mm`.
pub fn measured_point(commanded_mm: [f64; 2], spot_mm: [f64; 2]) -> MeasuredPoint {
    MeasuredPoint {
        x_mm: commanded_mm[0],
        y_mm: commanded_mm[1],
        dx_mm: spot_mm[0] - commanded_mm[0],
        dy_mm: spot_mm[1] - commanded_mm[1],
    }
}

/// The measured points (commanded, spot − commanded) of `frames`.
pub fn measured_points(frames: &[MeasuredFrame]) -> Vec<MeasuredPoint> {
    frames
        .iter()
        .map(|f| measured_point(f.row.commanded_mm, f.spot.board_mm))
        .collect()
}

/// Errors left after subtracting the fitted model at each point, mm.
fn residuals(report: &FitReport, points: &[MeasuredPoint]) -> Result<Vec<(f64, f64)>, String> {
    let model = report.model();
    points
        .iter()
        .map(|p| {
            let e = model
                .error_at(PointMm {
                    x_mm: p.x_mm,
                    y_mm: p.y_mm,
                })
                .map_err(|e| format!("model: {e}"))?;
            Ok((p.dx_mm - e.x_mm, p.dy_mm - e.y_mm))
        })
        .collect()
}

/// `calib camera --images DIR --points CSV`: the offline mode.
pub(crate) fn offline_command(
    a: &CameraRunArgs,
    images: &Path,
    points_csv: &Path,
) -> Result<String, String> {
    let text = std::fs::read_to_string(points_csv)
        .map_err(|e| format!("cannot read {}: {e}", points_csv.display()))?;
    let rows = read_frame_list(&text).map_err(|e| format!("{}: {e}", points_csv.display()))?;
    let l = layout(a.pitch_mm, 6, 4)?;
    let background = a
        .background
        .clone()
        .unwrap_or_else(|| images.join("background.png"));
    let intrinsics = match &a.intrinsics {
        Some(path) => {
            let bg = super::intrinsics::load_png(&background)?;
            super::intrinsics::load(Some(path), bg.width, bg.height)?
        }
        None => None,
    };
    let (view, frames) = measure_frames(images, &rows, &background, &l, intrinsics)?;
    let fitted = Fitted::new(measured_points(&frames), points_csv)?;
    let sigma = frames.iter().map(|f| f.spot.sigma_mm).fold(0.0, f64::max);
    let json =
        serde_json::to_string(&fitted.report(&view, sigma, None)).map_err(|e| e.to_string())?;
    write_outputs(a, &fitted, &fitted.after, &json)?;
    Ok(json)
}

/// Writes the files `a` asks for (everything is computed before: a
/// refusal writes nothing). `after`: the error vectors drawn as left
/// after the fit (predicted, or measured by a verification pass).
pub(super) fn write_outputs(
    a: &CameraRunArgs,
    fitted: &Fitted,
    after: &[(f64, f64)],
    json: &str,
) -> Result<(), String> {
    let svg = a
        .svg
        .as_ref()
        .map(|_| super::picture::error_vectors_svg(&fitted.points, after));
    let png = match &a.png {
        Some(_) => Some(super::picture::error_vectors_png(&fitted.points, after)?),
        None => None,
    };
    let writes: [(Option<&Path>, Option<&[u8]>); 4] = [
        (a.output.as_deref(), Some(fitted.firmware.as_bytes())),
        (a.report.as_deref(), Some(json.as_bytes())),
        (a.svg.as_deref(), svg.as_deref().map(str::as_bytes)),
        (a.png.as_deref(), png.as_deref()),
    ];
    for (path, bytes) in writes {
        if let (Some(path), Some(bytes)) = (path, bytes) {
            std::fs::write(path, bytes)
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        }
    }
    Ok(())
}
