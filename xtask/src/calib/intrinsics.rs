//! `cargo xtask calib camera intrinsics --views DIR --out FILE`: the
//! camera's interior orientation and radial distortion from several
//! laser-off views of the printed target at different tilts (Zhang's
//! method, `camera_calib::intrinsics`), saved as JSON for
//! `calib camera --intrinsics FILE`, which undistorts pixels before the
//! homography.

use std::path::{Path, PathBuf};

use camera_calib::camera::Intrinsics;
use camera_calib::image::GrayImage;
use camera_calib::intrinsics::fit_intrinsics;
use camera_calib::markers::{MarkerDetector, correspondences};
use camera_calib::measure::MIN_MARKERS;
use camera_calib::target::{GridSpec, TargetLayout};
use serde::{Deserialize, Serialize};

/// `calib camera intrinsics`
#[derive(clap::Args, Debug)]
pub struct IntrinsicsArgs {
    /// Directory of the views (every `*.png` in it; at least 3, the target
    /// tilted differently in each, same camera, focus and resolution).
    #[arg(long)]
    pub views: PathBuf,
    /// Where to write the intrinsics (JSON).
    #[arg(long)]
    pub out: PathBuf,
    /// Grid pitch of the printed target, mm.
    #[arg(long, default_value_t = 19.16)]
    pub pitch_mm: f64,
}

/// The intrinsics file: the lens and the image size it holds for.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct IntrinsicsFile {
    /// Image width, px.
    pub width: usize,
    /// Image height, px.
    pub height: usize,
    /// Focal length along x, px.
    pub fx: f64,
    /// Focal length along y, px.
    pub fy: f64,
    /// Principal point, px.
    pub cx: f64,
    /// Principal point, px.
    pub cy: f64,
    /// Radial distortion, r² term (normalised coordinates).
    pub k1: f64,
    /// Radial distortion, r⁴ term.
    pub k2: f64,
    /// Radial displacement at the image corner, % (from k1, k2).
    pub corner_distortion_percent: f64,
    /// RMS reprojection error of the fit, px.
    pub rms_px: f64,
    /// Views fitted.
    pub views: usize,
}

impl IntrinsicsFile {
    /// The lens, checked to be one (finite, positive focal lengths, the
    /// principal point on the image, distortion below 20 % at the corner).
    pub fn intrinsics(&self) -> Result<Intrinsics, String> {
        let i = Intrinsics {
            fx: self.fx,
            fy: self.fy,
            cx: self.cx,
            cy: self.cy,
            k1: self.k1,
            k2: self.k2,
        };
        let finite = [i.fx, i.fy, i.cx, i.cy, i.k1, i.k2]
            .iter()
            .all(|v| v.is_finite());
        let on_image =
            (0.0..self.width as f64).contains(&i.cx) && (0.0..self.height as f64).contains(&i.cy);
        if !finite || i.fx <= 0.0 || i.fy <= 0.0 || !on_image {
            return Err(format!("not a lens: {i:?}"));
        }
        if corner_distortion(&i, self.width, self.height).abs() > 0.2 {
            return Err(format!(
                "distortion {:.1} % at the corner is beyond this model",
                100.0 * corner_distortion(&i, self.width, self.height)
            ));
        }
        Ok(i)
    }
}

/// Relative radial displacement at the corner of a `width × height` image.
fn corner_distortion(i: &Intrinsics, width: usize, height: usize) -> f64 {
    let r2 = ((width as f64 / 2.0) / i.fx).powi(2) + ((height as f64 / 2.0) / i.fy).powi(2);
    i.k1 * r2 + i.k2 * r2 * r2
}

pub(super) fn load_png(path: &Path) -> Result<GrayImage, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    GrayImage::read_png(&bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// Runs `calib camera intrinsics`.
pub fn intrinsics_command(a: &IntrinsicsArgs) -> Result<String, String> {
    let layout = TargetLayout::for_grid(GridSpec {
        pitch_mm: a.pitch_mm,
        xi_max: 6,
        yi_max: 4,
    })?;
    let mut files: Vec<PathBuf> = std::fs::read_dir(&a.views)
        .map_err(|e| format!("cannot read {}: {e}", a.views.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")))
        .collect();
    files.sort();
    let mut size = None;
    let mut detector = None;
    let mut views = Vec::new();
    for path in &files {
        let img = load_png(path)?;
        if *size.get_or_insert((img.width, img.height)) != (img.width, img.height) {
            return Err(format!(
                "{}: {} × {} px, the other views are {:?}",
                path.display(),
                img.width,
                img.height,
                size
            ));
        }
        let det = match &mut detector {
            Some(d) => d,
            None => detector.insert(MarkerDetector::new(img.width, img.height)?),
        };
        let markers = det
            .detect(&img)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let found = markers
            .iter()
            .filter(|m| layout.tag(m.id).is_some())
            .count();
        if found < MIN_MARKERS {
            return Err(format!(
                "{}: {found} markers of the target found, need at least {MIN_MARKERS}",
                path.display()
            ));
        }
        views.push(correspondences(&markers, &layout));
    }
    let (width, height) = size.unwrap_or((0, 0));
    let fit =
        fit_intrinsics(&views, width, height).map_err(|e| format!("{}: {e}", a.views.display()))?;
    let i = fit.intrinsics;
    let file = IntrinsicsFile {
        width,
        height,
        fx: i.fx,
        fy: i.fy,
        cx: i.cx,
        cy: i.cy,
        k1: i.k1,
        k2: i.k2,
        corner_distortion_percent: 100.0 * corner_distortion(&i, width, height),
        rms_px: fit.rms_px,
        views: views.len(),
    };
    file.intrinsics()
        .map_err(|e| format!("the fitted lens is refused: {e}"))?;
    let json = serde_json::to_string(&file).map_err(|e| e.to_string())?;
    std::fs::write(&a.out, format!("{json}\n"))
        .map_err(|e| format!("cannot write {}: {e}", a.out.display()))?;
    Ok(json)
}

/// The intrinsics in `path`, if given, for frames of `width × height` px.
pub fn load(
    path: Option<&Path>,
    width: usize,
    height: usize,
) -> Result<Option<Intrinsics>, String> {
    let Some(path) = path else { return Ok(None) };
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let file: IntrinsicsFile =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    if (file.width, file.height) != (width, height) {
        return Err(format!(
            "{}: the intrinsics are for {} × {} px frames, these are {width} × {height}",
            path.display(),
            file.width,
            file.height
        ));
    }
    file.intrinsics()
        .map(Some)
        .map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests;
