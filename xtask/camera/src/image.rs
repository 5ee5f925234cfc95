//! 8-bit greyscale frames and their PNG files.

use std::io::Write;

/// An 8-bit greyscale image, row-major, `width × height` pixels.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GrayImage {
    /// Columns, px.
    pub width: usize,
    /// Rows, px.
    pub height: usize,
    /// `width·height` values, row 0 first.
    pub pixels: Vec<u8>,
}

impl GrayImage {
    /// A `width × height` image of value `v`.
    pub fn filled(width: usize, height: usize, v: u8) -> Self {
        Self {
            width,
            height,
            pixels: vec![v; width * height],
        }
    }

    /// The pixel-wise mean of `frames` (same size), rounded: averaging
    /// N exposures of a still scene divides the sensor noise by √N.
    pub fn mean(frames: &[GrayImage]) -> Result<Self, String> {
        let first = frames.first().ok_or("no frames to average")?;
        if frames
            .iter()
            .any(|f| (f.width, f.height) != (first.width, first.height))
        {
            return Err("frames to average differ in size".into());
        }
        let n = frames.len() as u32;
        let pixels = (0..first.pixels.len())
            .map(|i| {
                let sum: u32 = frames.iter().map(|f| u32::from(f.pixels[i])).sum();
                ((sum + n / 2) / n) as u8
            })
            .collect();
        Ok(Self {
            width: first.width,
            height: first.height,
            pixels,
        })
    }

    /// Value at column `x`, row `y` (`None` outside).
    pub fn get(&self, x: usize, y: usize) -> Option<u8> {
        (x < self.width)
            .then(|| self.pixels.get(y * self.width + x).copied())
            .flatten()
    }

    /// Decodes a PNG (greyscale, RGB or RGBA, 8 or 16 bits; colour is
    /// reduced to luma Rec. 601, 16 bits to the high byte).
    pub fn read_png(bytes: &[u8]) -> Result<Self, String> {
        let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let mut reader = decoder
            .read_info()
            .map_err(|e| format!("not a PNG image: {e}"))?;
        let size = reader
            .output_buffer_size()
            .ok_or_else(|| "PNG image too large".to_owned())?;
        let mut buf = vec![0; size];
        let info = reader
            .next_frame(&mut buf)
            .map_err(|e| format!("bad PNG data: {e}"))?;
        let (width, height) = (info.width as usize, info.height as usize);
        let channels = info.color_type.samples();
        let data = buf
            .get(..width * height * channels)
            .ok_or("short PNG data")?;
        let pixels = match channels {
            1 | 2 => data.chunks_exact(channels).map(|c| c[0]).collect(),
            _ => data
                .chunks_exact(channels)
                .map(|c| {
                    let y =
                        0.299 * f64::from(c[0]) + 0.587 * f64::from(c[1]) + 0.114 * f64::from(c[2]);
                    y.round().clamp(0.0, 255.0) as u8
                })
                .collect(),
        };
        Ok(Self {
            width,
            height,
            pixels,
        })
    }

    /// Encodes as an 8-bit greyscale PNG.
    pub fn write_png(&self, out: impl Write) -> Result<(), String> {
        let w = u32::try_from(self.width).map_err(|_| "image too wide")?;
        let h = u32::try_from(self.height).map_err(|_| "image too tall")?;
        let mut encoder = png::Encoder::new(out, w, h);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer
            .write_image_data(&self.pixels)
            .map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trip_and_garbage_is_refused() {
        let mut img = GrayImage::filled(7, 3, 9);
        img.pixels[8] = 200;
        let mut bytes = Vec::new();
        img.write_png(&mut bytes).unwrap();
        assert_eq!(GrayImage::read_png(&bytes).unwrap(), img);
        assert_eq!(img.get(1, 1), Some(200));
        assert_eq!(img.get(7, 0), None);
        assert!(
            GrayImage::read_png(b"not a png")
                .unwrap_err()
                .contains("not a PNG")
        );
    }
}
