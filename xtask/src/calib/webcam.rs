//! Webcam capture over V4L2 (the `webcam` feature: the `v4l` crate,
//! whose bindings are generated with bindgen at build time, so building
//! it needs libclang, e.g. Debian's `libclang-dev`). The grey level is
//! the luma of YUYV frames, or GREY frames as they are.

use std::path::Path;
use std::time::Duration;

use camera_calib::image::GrayImage;
use v4l::buffer::Type;
use v4l::io::mmap::Stream;
use v4l::io::traits::CaptureStream;
use v4l::video::Capture;
use v4l::{Device, FourCC};

use super::frame_source::FrameSource;

/// Buffers the driver fills in turn (also the stale frames dropped
/// before each capture).
const BUFFERS: u32 = 4;

/// An open V4L2 capture device.
pub struct Webcam {
    stream: Stream<'static>,
    /// Keeps the device open for the stream.
    _device: Device,
    width: usize,
    height: usize,
    /// Bytes per row.
    stride: usize,
    /// Bytes per pixel (2 for YUYV, 1 for GREY); the luma is the first.
    step: usize,
}

impl Webcam {
    /// Opens `device` in YUYV (or GREY) at its current resolution.
    pub fn open(device: &Path) -> Result<Self, String> {
        let err =
            |what: &str, e: std::io::Error| format!("camera {}: {what}: {e}", device.display());
        let dev = Device::with_path(device).map_err(|e| err("open", e))?;
        let mut format = dev.format().map_err(|e| err("format", e))?;
        format.fourcc = FourCC::new(b"YUYV");
        let format = dev.set_format(&format).map_err(|e| err("set format", e))?;
        let step = match &format.fourcc.repr {
            b"YUYV" => 2,
            b"GREY" => 1,
            other => {
                return Err(format!(
                    "camera {}: gives {} frames; this capture reads YUYV or GREY",
                    device.display(),
                    String::from_utf8_lossy(other)
                ));
            }
        };
        let mut stream = Stream::with_buffers(&dev, Type::VideoCapture, BUFFERS)
            .map_err(|e| err("buffers", e))?;
        stream.set_timeout(Duration::from_secs(5));
        Ok(Self {
            stream,
            _device: dev,
            width: format.width as usize,
            height: format.height as usize,
            stride: format.stride as usize,
            step,
        })
    }

    /// The luma of the next frame.
    fn next_frame(&mut self) -> Result<GrayImage, String> {
        let (buf, _) = self
            .stream
            .next()
            .map_err(|e| format!("camera capture: {e}"))?;
        let (w, h, stride, step) = (self.width, self.height, self.stride, self.step);
        if buf.len() < stride * h || stride < w * step {
            return Err(format!(
                "camera capture: a frame of {} bytes for {w} × {h} px",
                buf.len()
            ));
        }
        let pixels = (0..h)
            .flat_map(|y| (0..w).map(move |x| y * stride + x * step))
            .map(|i| buf[i])
            .collect();
        Ok(GrayImage {
            width: w,
            height: h,
            pixels,
        })
    }
}

impl FrameSource for Webcam {
    fn capture(&mut self, n: usize) -> Result<GrayImage, String> {
        // Frames already queued were exposed before now.
        for _ in 0..BUFFERS {
            self.next_frame()?;
        }
        let frames = (0..n.max(1))
            .map(|_| self.next_frame())
            .collect::<Result<Vec<_>, _>>()?;
        GrayImage::mean(&frames)
    }
}
