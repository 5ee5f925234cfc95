use super::*;
use crate::camera::{Camera, INTRINSICS_VIEW_EYES, Intrinsics};
use crate::homography::fit_homography;
use crate::markers::{MarkerDetector, correspondences};
use crate::render::{Exposure, VirtualCamera};
use crate::target::{GridSpec, TargetLayout};

/// Worst board-plane error (mm) of mapping every grid point's image
/// through the homography fitted to the markers, with or without undistortion.
fn worst_grid_error_mm(
    vc: &VirtualCamera,
    corners: &[Correspondence],
    intr: Option<&Intrinsics>,
) -> f64 {
    let undistort = |p: [f64; 2]| intr.map_or(p, |k| k.undistort_pixel(p));
    let pairs: Vec<Correspondence> = corners
        .iter()
        .map(|c| Correspondence {
            image_px: undistort(c.image_px),
            ..*c
        })
        .collect();
    let fit = fit_homography(&pairs).unwrap();
    vc.layout
        .grid_points_mm()
        .into_iter()
        .map(|g| {
            let b = fit
                .image_to_board
                .apply(undistort(vc.camera.project(g).unwrap()))
                .unwrap();
            (b[0] - g[0]).hypot(b[1] - g[1])
        })
        .fold(0.0, f64::max)
}

#[test]
fn zhang_recovers_the_lens_and_removes_half_a_percent_of_distortion() {
    let k1 = Intrinsics::k1_for_corner_distortion(
        0.005,
        1280.0,
        720.0,
        Camera::reference(0.0).intrinsics.fx,
    );
    let layout = TargetLayout::for_grid(GridSpec::default()).unwrap();
    let mut det = MarkerDetector::new(1280, 720).unwrap();
    let mut views = Vec::new();
    let mut cams = Vec::new();
    for (i, eye) in INTRINSICS_VIEW_EYES.into_iter().enumerate() {
        let vc = VirtualCamera {
            camera: Camera::reference(k1).from_eye(eye).unwrap(),
            layout: layout.clone(),
            exposure: Exposure::default(),
        };
        let img = vc.render(&[], i as u64);
        let markers = det.detect(&img).unwrap();
        assert!(markers.len() >= 12, "view {i}: {} markers", markers.len());
        views.push(correspondences(&markers, &layout));
        cams.push(vc);
    }
    let fit = fit_intrinsics(&views, 1280, 720)
        .map_err(|e| e.to_string())
        .unwrap();
    let truth = cams[0].camera.intrinsics;
    let i = fit.intrinsics;
    eprintln!("fit {i:?} rms {:.3} px; truth {truth:?}", fit.rms_px);
    assert!(fit.rms_px < 0.3, "{}", fit.rms_px);
    assert!(
        (i.fx / truth.fx - 1.0).abs() < 0.01 && (i.fy / truth.fy - 1.0).abs() < 0.01,
        "{i:?}"
    );
    assert!(
        (i.cx - truth.cx).abs() < 8.0 && (i.cy - truth.cy).abs() < 8.0,
        "{i:?}"
    );
    // Distortion at the image corner (beyond the markers: k1 and k2 trade
    // off there) within 0.1 % of the true 0.5 %.
    let corner = Intrinsics::k1_for_corner_distortion(1.0, 1280.0, 720.0, i.fx);
    let fitted = (i.k1 + i.k2 / corner) / corner;
    assert!((fitted - 0.005).abs() < 0.001, "corner distortion {fitted}");

    let without = worst_grid_error_mm(&cams[0], &views[0], None);
    let with = worst_grid_error_mm(&cams[0], &views[0], Some(&i));
    eprintln!("worst grid error: {without:.3} mm without intrinsics, {with:.3} mm with");
    assert!(
        without > 0.05 && with < 0.02 && with < without / 4.0,
        "{without} -> {with}"
    );
}

#[test]
fn too_few_or_flat_views_are_refused() {
    assert_eq!(
        fit_intrinsics(&[vec![], vec![]], 1280, 720),
        Err(IntrinsicsError::TooFewViews(2))
    );
    let short = vec![
        Correspondence {
            board_mm: [0.0, 0.0],
            image_px: [1.0, 1.0]
        };
        3
    ];
    let e = fit_intrinsics(&[short.clone(), short.clone(), short], 1280, 720).unwrap_err();
    assert_eq!(
        e,
        IntrinsicsError::View(0, HomographyError::TooFewPoints(3))
    );
    assert!(e.to_string().starts_with("view 1:"));
}
