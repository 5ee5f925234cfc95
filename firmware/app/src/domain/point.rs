//! Board points: where the spot goes, in the board frame (x right, y up,
//! origin at Q), centimetres.

use kinematics_core::{BoardPoint, PointMm};

use super::units::{galvo_mm_from_cm, mm_from_cm};

/// Largest board coordinate magnitude accepted anywhere (command line,
/// saved presets), cm.
pub const BOARD_LIMIT_CM: f64 = 200.0;

/// A board point, cm (board frame: x right, y up, origin at Q).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PointCm {
    /// Board x, cm.
    pub x_cm: f64,
    /// Board y, cm.
    pub y_cm: f64,
}

impl PointCm {
    /// The point `(x_cm, y_cm)`, cm.
    pub const fn new(x_cm: f64, y_cm: f64) -> Self {
        Self { x_cm, y_cm }
    }

    /// The same point in the geometry's type (`kinematics-core`, cm).
    pub fn board(self) -> BoardPoint {
        BoardPoint::new(self.x_cm, self.y_cm)
    }

    /// The point of the geometry's type `p` (cm).
    pub fn from_board(p: BoardPoint) -> Self {
        Self::new(p.x_cm, p.y_cm)
    }

    /// The same point in millimetres.
    pub fn mm(self) -> PointMm {
        PointMm::new(mm_from_cm(self.x_cm), mm_from_cm(self.y_cm))
    }

    /// The same point as the galvo takes it: `[x, y]` mm, `f32`.
    pub fn galvo_mm(self) -> [f32; 2] {
        [galvo_mm_from_cm(self.x_cm), galvo_mm_from_cm(self.y_cm)]
    }
}
