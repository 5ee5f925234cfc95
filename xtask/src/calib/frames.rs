//! `cargo xtask calib frames`: runs the grid in the simulator with a
//! build error and writes what the virtual camera sees: a laser-off
//! `background.png`, one PNG per dwell, and `points.csv` (the commanded
//! points), the input of `calib camera --images DIR --points DIR/points.csv`;
//! `truth.csv` (where each spot really was, same columns), and with
//! `--views N` laser-off views from N camera positions in `views/`, the
//! input of `calib camera intrinsics --views DIR/views`.

use std::fmt::Write as _;
use std::path::PathBuf;

use camera_calib::camera::{Camera, INTRINSICS_VIEW_EYES, Intrinsics};
use camera_calib::render::{Exposure, LaserSpot, VirtualCamera};
use laser_sim::physics::PhysicalGimbal;
use laser_sim::script::parse_script;
use laser_sim::world::{SimOptions, run};

/// `calib frames`
#[derive(clap::Args, Debug)]
pub struct FramesArgs {
    /// Directory to write the frames and `points.csv` into (created).
    #[arg(long)]
    out: PathBuf,
    /// Board roll of the simulated build, degrees.
    #[arg(long, default_value_t = 1.0)]
    roll_deg: f64,
    /// Yaw servo mounting error of the simulated build, degrees.
    #[arg(long, default_value_t = 0.8)]
    yaw_zero_deg: f64,
    /// Keep every Nth grid dwell (1: all 117).
    #[arg(long, default_value_t = 1)]
    every: usize,
    /// Sensor scale: 1 = 1280 × 720, 0.5 = 640 × 360 (same view).
    #[arg(long, default_value_t = 1.0)]
    scale: f64,
    /// Radial distortion at the image corner, % (0.5 = 0.5 %).
    #[arg(long, default_value_t = 0.0)]
    distortion_percent: f64,
    /// Also write this many laser-off views from around the camera
    /// (`views/view_N.png`, 3 to 5) for `calib camera intrinsics`.
    #[arg(long, default_value_t = 0)]
    pub(super) views: usize,
    /// Exposures averaged per frame (the background gets 8).
    #[arg(long, default_value_t = 1)]
    pub(super) exposures: usize,
}

impl FramesArgs {
    /// Every dwell's frame, one exposure each, no views.
    #[cfg(test)]
    pub(super) fn for_test(out: &std::path::Path, every: usize, distortion_percent: f64) -> Self {
        Self {
            out: out.into(),
            roll_deg: 1.0,
            yaw_zero_deg: 0.8,
            every,
            scale: 1.0,
            distortion_percent,
            views: 0,
            exposures: 1,
        }
    }
}

/// The reference camera scaled to `scale` of 1280 × 720.
pub fn scaled_camera(scale: f64, distortion_percent: f64) -> Camera {
    let mut cam = Camera::reference(0.0);
    let i = &mut cam.intrinsics;
    cam.width = (1280.0 * scale).round() as usize;
    cam.height = (720.0 * scale).round() as usize;
    i.fx *= scale;
    i.fy *= scale;
    i.cx = (cam.width as f64 - 1.0) / 2.0;
    i.cy = (cam.height as f64 - 1.0) / 2.0;
    i.k1 = Intrinsics::k1_for_corner_distortion(
        distortion_percent / 100.0,
        cam.width as f64,
        cam.height as f64,
        i.fx,
    );
    cam
}

/// A dwell's commanded point and where the spot really was, mm.
pub type CommandedAndReal = ([f64; 2], [f64; 2]);

/// Commanded and real spot positions (mm) of the grid on a build with
/// the board rolled `roll_deg` and the yaw servo off by `yaw_zero_deg`,
/// after the `setup` command lines.
pub fn grid_dwells(
    roll_deg: f64,
    yaw_zero_deg: f64,
    setup: &str,
) -> Result<Vec<CommandedAndReal>, String> {
    let mut physical = PhysicalGimbal::default();
    physical.gimbal.geometry.frame.pose.roll_deg = roll_deg;
    physical.gimbal.geometry.yaw.zero_deg = yaw_zero_deg;
    let script = parse_script(&format!(
        "{setup}set dwell_ms 50\npattern grid-full serpentine once\n"
    ))
    .map_err(|e| e.to_string())?;
    let report = run(SimOptions {
        script,
        until_idle: true,
        physical,
        ..SimOptions::default()
    });
    if !report.succeeded(false) {
        return Err(format!(
            "simulated grid run failed: {:?}",
            report.transcript
        ));
    }
    Ok(report
        .recording
        .dwells
        .iter()
        .map(|d| (d.target_mm(), d.spot_mm()))
        .collect())
}

pub(crate) fn frames_command(a: &FramesArgs) -> Result<String, String> {
    if a.every == 0 || a.exposures == 0 || !(0.25..=2.0).contains(&a.scale) {
        return Err("--every and --exposures must be >= 1 and --scale within 0.25..2".into());
    }
    if a.views > INTRINSICS_VIEW_EYES.len() || !(0.0..=5.0).contains(&a.distortion_percent.abs()) {
        return Err(format!(
            "--views must be at most {} and --distortion-percent within ±5",
            INTRINSICS_VIEW_EYES.len()
        ));
    }
    let dwells = grid_dwells(a.roll_deg, a.yaw_zero_deg, "")?;
    let vc = VirtualCamera {
        camera: scaled_camera(a.scale, a.distortion_percent),
        layout: super::camera::layout(19.16, 6, 4)?,
        exposure: Exposure::default(),
    };
    std::fs::create_dir_all(&a.out)
        .map_err(|e| format!("cannot create {}: {e}", a.out.display()))?;
    let scene = vc.scene();
    let save = |name: &str, img: &camera_calib::image::GrayImage| {
        let path = a.out.join(name);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)
                .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        }
        let file = std::fs::File::create(&path)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        img.write_png(std::io::BufWriter::new(file))
            .map_err(|e| format!("{}: {e}", path.display()))
    };
    for (k, eye) in INTRINSICS_VIEW_EYES.iter().take(a.views).enumerate() {
        let view = VirtualCamera {
            camera: vc.camera.from_eye(*eye).ok_or("bad view")?,
            ..vc.clone()
        };
        save(
            &format!("views/view_{k}.png"),
            &view.render(&[], 500 + k as u64),
        )?;
    }
    // 8 laser-off exposures averaged, as the online loop captures.
    save("background.png", &vc.averaged_frame(&scene, &[], 8, 1))?;
    let header = |what: &str| {
        format!("# {what} of each frame, mm (written by `cargo xtask calib frames`)\nimage,x,y\n")
    };
    let mut csv = header("commanded board point");
    let mut truth = header("where the spot really was");
    let mut n = 0;
    for (k, (target, spot)) in dwells.iter().enumerate().step_by(a.every) {
        let name = format!("frame_{k:03}.png");
        let spots = [LaserSpot::at(*spot)];
        save(
            &name,
            &vc.averaged_frame(&scene, &spots, a.exposures, 1000 + k as u64),
        )?;
        let _ = writeln!(csv, "{name},{},{}", target[0], target[1]);
        let _ = writeln!(truth, "{name},{},{}", spot[0], spot[1]);
        n += 1;
    }
    for (file, text) in [("points.csv", csv), ("truth.csv", truth)] {
        let path = a.out.join(file);
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    Ok(format!(
        "{{\"frames\":{n},\"dir\":{:?}}}",
        a.out.display().to_string()
    ))
}
