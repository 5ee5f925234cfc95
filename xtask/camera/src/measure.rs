//! From frames to board millimetres: the board's homography from the
//! markers of a (laser-off) frame, then each spot mapped onto the board
//! with its uncertainty.

use nalgebra::Matrix2;

use crate::camera::Intrinsics;
use crate::homography::{HomographyError, HomographyFit, fit_homography};
use crate::image::GrayImage;
use crate::markers::{MarkerDetector, correspondences};
use crate::spot::{SpotError, SpotMeasurement, check_exposure, detect_spot};
use crate::target::TargetLayout;

/// Fewest markers accepted for a homography (12 corners spread over the board).
pub const MIN_MARKERS: usize = 3;

/// Why the board could not be located in a frame.
#[derive(Debug, Clone, PartialEq)]
pub enum BoardError {
    /// The frame is unusable (saturated or black).
    Exposure(SpotError),
    /// No marker of the board was decoded.
    NoMarkers,
    /// Fewer than [`MIN_MARKERS`] markers of the board were decoded.
    TooFewMarkers {
        /// Ids found.
        found: Vec<u16>,
    },
    /// The marker detector failed.
    Detector(String),
    /// The corners do not determine a homography.
    Homography(HomographyError),
}

impl std::fmt::Display for BoardError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Exposure(e) => e.fmt(f),
            Self::NoMarkers => write!(
                f,
                "no markers of the target found (is the printed target in view?)"
            ),
            Self::TooFewMarkers { found } => write!(
                f,
                "too few markers for a homography: found {} ({found:?}), need at least {MIN_MARKERS}",
                found.len()
            ),
            Self::Detector(e) => write!(f, "marker detector: {e}"),
            Self::Homography(e) => write!(f, "homography: {e}"),
        }
    }
}

/// The board as seen by one camera set-up.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardView {
    /// Undistorted image px ↔ board mm.
    pub fit: HomographyFit,
    /// Ids of the markers used.
    pub markers: Vec<u16>,
    /// The lens model applied before the homography, if known.
    pub intrinsics: Option<Intrinsics>,
}

/// A spot on the board.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpotOnBoard {
    /// Board coordinates, mm.
    pub board_mm: [f64; 2],
    /// 1-σ radial uncertainty, mm (centroid noise and homography error).
    pub sigma_mm: f64,
}

/// Locates the board in `image` from its markers; pixels are undistorted
/// with `intrinsics` first when given.
pub fn locate_board(
    detector: &mut MarkerDetector,
    image: &GrayImage,
    layout: &TargetLayout,
    intrinsics: Option<Intrinsics>,
) -> Result<BoardView, BoardError> {
    check_exposure(image).map_err(BoardError::Exposure)?;
    let markers = detector.detect(image).map_err(BoardError::Detector)?;
    let mut pairs = correspondences(&markers, layout);
    let found: Vec<u16> = markers
        .iter()
        .map(|m| m.id)
        .filter(|&id| layout.tag(id).is_some())
        .collect();
    if found.is_empty() {
        return Err(BoardError::NoMarkers);
    }
    if found.len() < MIN_MARKERS {
        return Err(BoardError::TooFewMarkers { found });
    }
    if let Some(k) = &intrinsics {
        for c in &mut pairs {
            c.image_px = k.undistort_pixel(c.image_px);
        }
    }
    let fit = fit_homography(&pairs).map_err(BoardError::Homography)?;
    Ok(BoardView {
        fit,
        markers: found,
        intrinsics,
    })
}

impl BoardView {
    /// The board point of `spot`; `None` if it maps to infinity.
    pub fn spot_on_board(&self, spot: &SpotMeasurement) -> Option<SpotOnBoard> {
        let px = match &self.intrinsics {
            Some(k) => k.undistort_pixel(spot.image_px),
            None => spot.image_px,
        };
        let board_mm = self.fit.image_to_board.apply(px)?;
        let j: Matrix2<f64> = self.fit.image_to_board.jacobian(px);
        // Homography error at a point ≈ corner RMS · √(8 / n) px.
        let h_px = self.fit.rms_px * (8.0 / self.fit.n as f64).sqrt();
        let var_px = spot.sigma_px.powi(2) + h_px.powi(2);
        let sigma_mm = (var_px * (j * j.transpose()).trace()).sqrt();
        Some(SpotOnBoard { board_mm, sigma_mm })
    }

    /// Detects the spot in `frame` against `background` and maps it.
    pub fn measure(
        &self,
        background: &GrayImage,
        frame: &GrayImage,
    ) -> Result<SpotOnBoard, SpotError> {
        let spot = detect_spot(background, frame)?;
        self.spot_on_board(&spot).ok_or(SpotError::NoSpot)
    }
}

#[cfg(test)]
mod tests;
