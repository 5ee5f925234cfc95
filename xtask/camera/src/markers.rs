//! AprilTag 36h11 detection (the `kornia-apriltag` detector) and the
//! marker corners as board ↔ image correspondences.

use kornia_apriltag::family::TagFamilyKind;
use kornia_apriltag::{AprilTagDecoder, DecodeTagsConfig};
use kornia_image::{Image, ImageSize};

use crate::homography::Correspondence;
use crate::image::GrayImage;
use crate::target::TargetLayout;

/// A decoded marker.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Tag id.
    pub id: u16,
    /// Black-border corners, px, in tag order top-left, top-right,
    /// bottom-right, bottom-left (as [`crate::target::TagPlacement::corners_mm`]).
    pub corners_px: [[f64; 2]; 4],
    /// The detector's decision margin (higher = more confident).
    pub margin: f64,
}

/// A reusable detector for one image size.
pub struct MarkerDetector {
    decoder: AprilTagDecoder,
    width: usize,
    height: usize,
}

impl MarkerDetector {
    /// A detector for `width × height` frames.
    pub fn new(width: usize, height: usize) -> Result<Self, String> {
        let config =
            DecodeTagsConfig::new(vec![TagFamilyKind::Tag36H11]).map_err(|e| e.to_string())?;
        let decoder =
            AprilTagDecoder::new(config, ImageSize { width, height }).map_err(|e| e.to_string())?;
        Ok(Self {
            decoder,
            width,
            height,
        })
    }

    /// The tag36h11 markers in `image` (every id the family knows; the
    /// caller keeps those on its board). Ids seen twice are dropped.
    pub fn detect(&mut self, image: &GrayImage) -> Result<Vec<Marker>, String> {
        if (image.width, image.height) != (self.width, self.height) {
            *self = Self::new(image.width, image.height)?;
        }
        let size = ImageSize {
            width: image.width,
            height: image.height,
        };
        let img = Image::<u8, 1>::new(size, image.pixels.clone()).map_err(|e| e.to_string())?;
        let detections = self.decoder.decode(&img).map_err(|e| e.to_string());
        self.decoder.clear();
        let mut markers: Vec<Marker> = detections?
            .into_iter()
            .map(|d| {
                // The detector puts pixel centres at +0.5 (pixel-corner
                // origin); this crate puts them at integers.
                let corner = |x: f32, y: f32| {
                    let p = d.quad.homography_project(x, y);
                    [f64::from(p.x) - 0.5, f64::from(p.y) - 0.5]
                };
                Marker {
                    id: d.id,
                    corners_px: [
                        corner(-1.0, -1.0),
                        corner(1.0, -1.0),
                        corner(1.0, 1.0),
                        corner(-1.0, 1.0),
                    ],
                    margin: f64::from(d.decision_margin),
                }
            })
            .collect();
        let ids: Vec<u16> = markers.iter().map(|m| m.id).collect();
        markers.retain(|m| ids.iter().filter(|&&i| i == m.id).count() == 1);
        markers.sort_by_key(|m| m.id);
        Ok(markers)
    }
}

/// Corner correspondences of the markers that are on `layout`.
pub fn correspondences(markers: &[Marker], layout: &TargetLayout) -> Vec<Correspondence> {
    markers
        .iter()
        .filter_map(|m| layout.tag(m.id).map(|t| (m, t.corners_mm())))
        .flat_map(|(m, board)| {
            board
                .into_iter()
                .zip(m.corners_px)
                .map(|(board_mm, image_px)| Correspondence { board_mm, image_px })
        })
        .collect()
}
