use camera_calib::image::GrayImage;
use camera_calib::offline::{measure_frames, read_frame_list};

use super::*;
use crate::calib::camera::CameraRunArgs;
use crate::calib::frames::{FramesArgs, frames_command};
use crate::calib::run_command;

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("xtask-intrinsics-{}-{name}", std::process::id()))
}

/// Worst and RMS distance (mm) of the measured spots from where they
/// really were.
fn spot_errors(dir: &Path, intrinsics: Option<Intrinsics>) -> (f64, f64) {
    let read = |f: &str| read_frame_list(&std::fs::read_to_string(dir.join(f)).unwrap()).unwrap();
    let (rows, truth) = (read("points.csv"), read("truth.csv"));
    let layout = crate::calib::camera::layout(19.16, 6, 4).unwrap();
    let (_, frames) =
        measure_frames(dir, &rows, &dir.join("background.png"), &layout, intrinsics).unwrap();
    let errors: Vec<f64> = frames
        .iter()
        .zip(&truth)
        .map(|(f, t)| {
            assert_eq!(f.row.image, t.image);
            let [x, y] = f.spot.board_mm;
            (x - t.commanded_mm[0]).hypot(y - t.commanded_mm[1])
        })
        .collect();
    let worst = errors.iter().copied().fold(0.0, f64::max);
    let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    (worst, rms)
}

/// Issue 22: with 0.5 % radial distortion rendered by the virtual camera,
/// `calib camera intrinsics` on five views finds the lens, and measuring
/// the same frames through it removes the distortion's share of the spot
/// error (same frames, same noise: only the mapping differs).
#[test]
fn the_intrinsics_command_removes_half_a_percent_of_distortion() {
    let dir = tmp("frames");
    let mut frames = FramesArgs::for_test(&dir, 3, 0.5);
    frames.views = 5;
    frames.exposures = 4;
    frames_command(&frames).unwrap();
    let file = tmp("intrinsics.json");
    let json = intrinsics_command(&IntrinsicsArgs {
        views: dir.join("views"),
        out: file.clone(),
        pitch_mm: 19.16,
    })
    .unwrap();
    let fitted: IntrinsicsFile = serde_json::from_str(&json).unwrap();
    assert_eq!((fitted.width, fitted.height, fitted.views), (1280, 720, 5));
    assert!(fitted.rms_px < 0.3, "{fitted:?}");
    assert!(
        (fitted.corner_distortion_percent - 0.5).abs() < 0.1,
        "{fitted:?}"
    );
    let lens = load(Some(&file), 1280, 720).unwrap();
    let (worst_without, rms_without) = spot_errors(&dir, None);
    let (worst_with, rms_with) = spot_errors(&dir, lens);
    eprintln!(
        "0.5 % distortion, spot error vs truth: without intrinsics worst {worst_without:.3} mm \
         RMS {rms_without:.3} mm; with worst {worst_with:.3} mm RMS {rms_with:.3} mm; lens {fitted:?}"
    );
    assert!(rms_with < 0.7 * rms_without, "{rms_without} -> {rms_with}");
    assert!(
        worst_with < worst_without && worst_with <= 0.15,
        "{worst_without} -> {worst_with}"
    );

    // The offline command takes the file, and refuses it for other frames.
    let mut a = CameraRunArgs::for_test(
        &dir,
        &dir.join("points.csv"),
        &tmp("err.txt"),
        &tmp("report.json"),
        &tmp("errors.svg"),
    );
    a.intrinsics = Some(file.clone());
    let report: serde_json::Value = serde_json::from_str(&run_command(&a).unwrap()).unwrap();
    assert_eq!(report["intrinsics"], true);
    let mut other = fitted.clone();
    other.width = 640;
    std::fs::write(&file, serde_json::to_string(&other).unwrap()).unwrap();
    let e = run_command(&a).unwrap_err();
    assert!(e.contains("intrinsics are for 640 × 720 px"), "{e}");
    for f in ["err.txt", "report.json", "errors.svg", "intrinsics.json"] {
        let _ = std::fs::remove_file(tmp(f));
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn too_few_views_or_a_view_without_markers_are_refused_naming_it() {
    let dir = tmp("bad-views");
    std::fs::create_dir_all(&dir).unwrap();
    let grey = GrayImage::filled(160, 120, 128);
    for k in 0..2 {
        let f = std::fs::File::create(dir.join(format!("v{k}.png"))).unwrap();
        grey.write_png(f).unwrap();
    }
    let args = IntrinsicsArgs {
        views: dir.clone(),
        out: tmp("never.json"),
        pitch_mm: 19.16,
    };
    let e = intrinsics_command(&args).unwrap_err();
    assert!(e.contains("v0.png: 0 markers of the target found"), "{e}");
    assert!(!tmp("never.json").exists());
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let e = intrinsics_command(&args).unwrap_err();
    assert!(e.contains("at least 3 views"), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}
