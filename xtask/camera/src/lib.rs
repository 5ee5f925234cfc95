//! Camera calibration of the laser spot (issue 22, SPEC §5): the printable
//! AprilTag target, a virtual camera that renders it, marker detection,
//! the board-to-image homography, laser spot detection, and the camera's
//! intrinsics from several views (Zhang's method).
//!
//! Units: board coordinates in mm (board frame B of SPEC §4.1: x right,
//! y up, origin at the grid centre); image coordinates in px (x right,
//! y down, pixel centres at integer coordinates).

pub mod camera;
pub mod homography;
pub mod image;
pub mod intrinsics;
mod lm;
pub mod markers;
pub mod measure;
pub mod noise;
pub mod offline;
pub mod print;
pub mod render;
pub mod spot;
pub mod target;
