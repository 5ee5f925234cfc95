//! Where `calib camera`'s online mode gets its frames: the simulator's
//! virtual camera (`--camera sim`), or a V4L2 webcam (`--camera
//! /dev/videoN`, with the `webcam` feature).

use std::path::{Path, PathBuf};

use camera_calib::image::GrayImage;
use camera_calib::render::{Exposure, LaserSpot, Scene, VirtualCamera};
use camera_calib::target::TargetLayout;
use laser_sim::spot_feed::{FeedSample, beside};

pub use super::frame_source::FrameSource;

/// The simulator's virtual camera: renders the printed target and the
/// spot where the simulator's spot feed says it really is (when lit).
pub struct SimCamera {
    feed: PathBuf,
    camera: VirtualCamera,
    scene: Scene,
    /// Exposures taken (the noise seed of the next).
    shots: u64,
}

impl SimCamera {
    /// The reference camera (1280 × 720, 24° off the board normal) with
    /// `distortion_percent` radial distortion at the image corner, reading
    /// the spot from `feed`.
    pub fn new(feed: PathBuf, layout: TargetLayout, distortion_percent: f64) -> Self {
        let camera = VirtualCamera {
            camera: super::frames::scaled_camera(1.0, distortion_percent),
            layout,
            exposure: Exposure::default(),
        };
        let scene = camera.scene();
        Self {
            feed,
            camera,
            scene,
            shots: 0,
        }
    }
}

impl FrameSource for SimCamera {
    fn capture(&mut self, n: usize) -> Result<GrayImage, String> {
        let now = FeedSample::read(&self.feed)?;
        let spots: Vec<LaserSpot> = match (now.lit, now.spot_mm) {
            (true, Some(p)) => vec![LaserSpot::at(p)],
            _ => Vec::new(),
        };
        let n = n.max(1);
        let frame = self
            .camera
            .averaged_frame(&self.scene, &spots, n, 7 + self.shots);
        self.shots += n as u64;
        Ok(frame)
    }
}

/// The camera `--camera NAME` names, for the board at `port`.
pub fn open(
    name: &str,
    port: &Path,
    spot_feed: Option<&Path>,
    layout: &TargetLayout,
    sim_distortion_percent: f64,
) -> Result<Box<dyn FrameSource>, String> {
    if name == "sim" {
        if !(0.0..=5.0).contains(&sim_distortion_percent.abs()) {
            return Err("--sim-distortion-percent must be within ±5".into());
        }
        let feed = spot_feed.map_or_else(|| beside(port), Path::to_path_buf);
        // Fail now, before the board moves, if the feed is not there.
        FeedSample::read(&feed)?;
        return Ok(Box::new(SimCamera::new(
            feed,
            layout.clone(),
            sim_distortion_percent,
        )));
    }
    webcam(Path::new(name))
}

#[cfg(feature = "webcam")]
fn webcam(device: &Path) -> Result<Box<dyn FrameSource>, String> {
    super::webcam::Webcam::open(device).map(|w| Box::new(w) as Box<dyn FrameSource>)
}

#[cfg(not(feature = "webcam"))]
fn webcam(device: &Path) -> Result<Box<dyn FrameSource>, String> {
    Err(format!(
        "camera {}: this xtask is built without webcam capture; build it with \
         `cargo xtask --features webcam …` (see docs/camera-calibration.md), \
         or use --camera sim with the simulator",
        device.display()
    ))
}
