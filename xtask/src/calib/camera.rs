//! `cargo xtask calib target|camera|frames` (issue 22): the printable
//! target, the offline camera calibration (frames + commanded points →
//! `set err.*` lines, JSON report, SVG of the error vectors), and frames
//! of the simulator's virtual camera.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use camera_calib::offline::{MeasuredFrame, measure_frames, read_frame_list};
use camera_calib::target::{GridSpec, TargetLayout};
use kinematics_core::{FitReport, MeasuredPoint, PointMm, fit};
use serde::Serialize;

use super::{AxisOut, firmware_commands};

/// `calib target`
#[derive(clap::Args, Debug)]
pub struct TargetArgs {
    /// Where to write the SVG (print at 100 %).
    #[arg(long)]
    out: PathBuf,
    /// Grid pitch, mm (SPEC §4.1).
    #[arg(long, default_value_t = 19.16)]
    pitch_mm: f64,
    /// Grid half-width in cells.
    #[arg(long, default_value_t = 6)]
    xi_max: i32,
    /// Grid half-height in cells.
    #[arg(long, default_value_t = 4)]
    yi_max: i32,
}

/// `calib camera`
#[derive(clap::Args, Debug)]
pub struct CameraArgs {
    /// Directory of the frames (PNG).
    #[arg(long)]
    images: PathBuf,
    /// Frame list: CSV `image,x,y` (commanded board point of each frame, mm).
    #[arg(long)]
    points: PathBuf,
    /// Laser-off frame of the same view (default: IMAGES/background.png).
    #[arg(long)]
    background: Option<PathBuf>,
    /// Write the model as firmware `set err.*` command lines here.
    #[arg(long)]
    output: Option<PathBuf>,
    /// Write the JSON report here too (it is always printed).
    #[arg(long)]
    report: Option<PathBuf>,
    /// Write an SVG of the error vectors (measured, and left after the fit) here.
    #[arg(long)]
    svg: Option<PathBuf>,
    /// Grid pitch of the printed target, mm.
    #[arg(long, default_value_t = 19.16)]
    pitch_mm: f64,
}

impl CameraArgs {
    /// Arguments writing every output, for the tests.
    #[cfg(test)]
    pub(super) fn for_test(
        images: &Path,
        points: &Path,
        output: &Path,
        report: &Path,
        svg: &Path,
    ) -> Self {
        Self {
            images: images.into(),
            points: points.into(),
            background: None,
            output: Some(output.into()),
            report: Some(report.into()),
            svg: Some(svg.into()),
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
    fn of(errors: impl Iterator<Item = (f64, f64)>) -> Self {
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

#[derive(Serialize)]
struct CameraReport {
    frames: usize,
    markers: Vec<u16>,
    reprojection_px: f64,
    spot_sigma_mm_max: f64,
    before: ErrorStats,
    after_predicted: ErrorStats,
    dx: AxisOut,
    dy: AxisOut,
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
    std::fs::write(&a.out, l.svg())
        .map_err(|e| format!("cannot write {}: {e}", a.out.display()))?;
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

/// The measured points (commanded, spot − commanded) of `frames`.
pub fn measured_points(frames: &[MeasuredFrame]) -> Vec<MeasuredPoint> {
    frames
        .iter()
        .map(|f| MeasuredPoint {
            x_mm: f.row.commanded_mm[0],
            y_mm: f.row.commanded_mm[1],
            dx_mm: f.spot.board_mm[0] - f.row.commanded_mm[0],
            dy_mm: f.spot.board_mm[1] - f.row.commanded_mm[1],
        })
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

pub(crate) fn camera_command(a: &CameraArgs) -> Result<String, String> {
    let text = std::fs::read_to_string(&a.points)
        .map_err(|e| format!("cannot read {}: {e}", a.points.display()))?;
    let rows = read_frame_list(&text).map_err(|e| format!("{}: {e}", a.points.display()))?;
    let l = layout(a.pitch_mm, 6, 4)?;
    let background = a
        .background
        .clone()
        .unwrap_or_else(|| a.images.join("background.png"));
    let (view, frames) = measure_frames(&a.images, &rows, &background, &l, None)?;
    let points = measured_points(&frames);
    let report = fit(&points).map_err(|e| format!("fit refused ({} frames): {e}", points.len()))?;
    let after = residuals(&report, &points)?;
    let firmware = match &a.output {
        Some(_) => Some(firmware_commands(&report, &a.points)?),
        None => None,
    };
    let json = serde_json::to_string(&CameraReport {
        frames: frames.len(),
        markers: view.markers.clone(),
        reprojection_px: view.fit.rms_px,
        spot_sigma_mm_max: frames.iter().map(|f| f.spot.sigma_mm).fold(0.0, f64::max),
        before: ErrorStats::of(points.iter().map(|p| (p.dx_mm, p.dy_mm))),
        after_predicted: ErrorStats::of(after.iter().copied()),
        dx: (&report.dx).into(),
        dy: (&report.dy).into(),
    })
    .map_err(|e| e.to_string())?;
    let svg = error_vectors_svg(&points, &after);
    // Everything is computed: only now write the files.
    let writes = [
        (a.output.as_deref(), firmware.as_deref()),
        (a.report.as_deref(), Some(json.as_str())),
        (a.svg.as_deref(), Some(svg.as_str())),
    ];
    for (path, text) in writes {
        if let (Some(path), Some(text)) = (path, text) {
            write(path, text)?;
        }
    }
    Ok(json)
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Error vectors, magnified: measured (red) and left after the fit (blue).
pub fn error_vectors_svg(points: &[MeasuredPoint], after: &[(f64, f64)]) -> String {
    let worst = points
        .iter()
        .map(|p| p.dx_mm.hypot(p.dy_mm))
        .fold(0.0, f64::max);
    let pitch = 19.16;
    // The longest arrow is one grid pitch.
    let gain = if worst > 0.0 { pitch / worst } else { 1.0 };
    let (xmax, ymax) = points.iter().fold((10.0f64, 10.0f64), |(a, b), p| {
        (a.max(p.x_mm.abs()), b.max(p.y_mm.abs()))
    });
    let (w, h) = (
        2.0 * (xmax + 2.0 * pitch),
        2.0 * (ymax + 2.0 * pitch) + 12.0,
    );
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{:.0}\" height=\"{:.0}\" viewBox=\"{:.2} {:.2} {w:.2} {h:.2}\">",
        w * 3.0,
        h * 3.0,
        -w / 2.0,
        -h / 2.0 + 6.0
    );
    let _ = writeln!(
        s,
        "<rect x=\"{:.2}\" y=\"{:.2}\" width=\"{w:.2}\" height=\"{h:.2}\" fill=\"white\"/>",
        -w / 2.0,
        -h / 2.0 + 6.0
    );
    let _ = writeln!(
        s,
        "<text x=\"{:.2}\" y=\"{:.2}\" font-size=\"4\" font-family=\"sans-serif\">error vectors x{gain:.1}: red measured (worst {worst:.3} mm), blue left after the fit</text>",
        -w / 2.0 + 3.0,
        -h / 2.0 + 11.0
    );
    for (p, (ax, ay)) in points.iter().zip(after) {
        let (x, y) = (p.x_mm, -p.y_mm);
        let _ = writeln!(
            s,
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"0.6\" fill=\"#444\"/>"
        );
        for (dx, dy, colour) in [(p.dx_mm, p.dy_mm, "#d22"), (*ax, *ay, "#22d")] {
            let _ = writeln!(
                s,
                "<line x1=\"{x:.2}\" y1=\"{y:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" stroke=\"{colour}\" stroke-width=\"0.5\"/>",
                x + gain * dx,
                y - gain * dy
            );
        }
    }
    s.push_str("</svg>\n");
    s
}
