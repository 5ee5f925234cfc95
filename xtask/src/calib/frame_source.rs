//! What the calibration reads frames from: the simulator's virtual camera
//! or a webcam ([`super::capture`] opens one).

use camera_calib::image::GrayImage;

/// A camera looking at the board.
pub trait FrameSource {
    /// The mean of `n` exposures taken from now on (grey levels).
    fn capture(&mut self, n: usize) -> Result<GrayImage, String>;
}
