//! Laser spot detection: the difference to a laser-off background frame,
//! thresholded against its noise, connected blobs, an intensity-weighted
//! sub-pixel centroid (unbiased with a saturated core, which is flat and
//! symmetric), rejection of reflections (faint blobs) and of frames with
//! no spot or two.

use crate::image::GrayImage;

/// Why a frame gave no spot.
#[derive(Debug, Clone, PartialEq)]
pub enum SpotError {
    /// The frame and the background differ in size.
    SizeMismatch,
    /// Most of the frame is at full scale: exposure too long.
    Saturated {
        /// Share of pixels at 255, %.
        percent: f64,
    },
    /// The frame is (nearly) black: lens covered or exposure too short.
    Black,
    /// Nothing brighter than the background's noise.
    NoSpot,
    /// Two blobs of comparable brightness.
    TwoSpots {
        /// Their centroids, px.
        at: [[f64; 2]; 2],
    },
}

impl std::fmt::Display for SpotError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::SizeMismatch => write!(f, "frame and background differ in size"),
            Self::Saturated { percent } => write!(
                f,
                "frame is saturated ({percent:.0} % of pixels at full scale): shorten the exposure"
            ),
            Self::Black => write!(f, "frame is black: check the lens cap and exposure"),
            Self::NoSpot => write!(
                f,
                "no laser spot found (is the laser on and the spot on the board?)"
            ),
            Self::TwoSpots { at } => write!(
                f,
                "two spots at ({:.1}, {:.1}) px and ({:.1}, {:.1}) px",
                at[0][0], at[0][1], at[1][0], at[1][1]
            ),
        }
    }
}

/// A detected spot.
#[derive(Debug, Clone, PartialEq)]
pub struct SpotMeasurement {
    /// Centroid, px.
    pub image_px: [f64; 2],
    /// 1-σ uncertainty of the centroid from sensor noise, px (per axis, the larger).
    pub sigma_px: f64,
    /// Pixels in the spot.
    pub pixels: usize,
    /// Of which at full scale.
    pub saturated: usize,
    /// Faint blobs ignored as reflections.
    pub reflections: usize,
}

/// Share of saturated pixels above which a frame is refused, %.
const SATURATED_PERCENT: f64 = 5.0;
/// Brightest level (99.9th percentile) below which a frame is black, DN.
const BLACK_DN: u8 = 24;
/// A second blob with at least this share of the main blob's light is a second spot.
const SECOND_SPOT_RATIO: f64 = 0.25;
/// Smallest lower bound of the detection threshold, DN.
const MIN_THRESHOLD_DN: f64 = 12.0;

/// Refuses saturated and black frames.
pub fn check_exposure(image: &GrayImage) -> Result<(), SpotError> {
    let mut hist = [0usize; 256];
    for &p in &image.pixels {
        hist[usize::from(p)] += 1;
    }
    let n = image.pixels.len().max(1);
    let percent = 100.0 * hist[255] as f64 / n as f64;
    if percent > SATURATED_PERCENT {
        return Err(SpotError::Saturated { percent });
    }
    let mut above = 0;
    let bright = (0..=255u8).rev().find(|&v| {
        above += hist[usize::from(v)];
        above * 1000 >= n
    });
    if bright.is_none_or(|b| b < BLACK_DN) {
        return Err(SpotError::Black);
    }
    Ok(())
}

/// Noise of the difference image, DN RMS (robust: 1.4826 · median |d|
/// over every 7th pixel).
fn difference_noise(bg: &[u8], frame: &[u8]) -> f64 {
    let mut hist = [0usize; 256];
    let mut n = 0;
    for (b, f) in bg.iter().zip(frame).step_by(7) {
        hist[usize::from(b.abs_diff(*f))] += 1;
        n += 1;
    }
    let mut seen = 0;
    let median = (0..256).find(|&v| {
        seen += hist[v];
        2 * seen >= n
    });
    1.4826 * median.unwrap_or(0) as f64 + 0.5
}

struct Blob {
    pixels: Vec<usize>,
    light: f64,
}

/// Finds the laser spot in `frame` against the laser-off `background`.
pub fn detect_spot(
    background: &GrayImage,
    frame: &GrayImage,
) -> Result<SpotMeasurement, SpotError> {
    if (background.width, background.height) != (frame.width, frame.height) {
        return Err(SpotError::SizeMismatch);
    }
    check_exposure(frame)?;
    let w = frame.width;
    let noise = difference_noise(&background.pixels, &frame.pixels);
    let threshold = (6.0 * noise).max(MIN_THRESHOLD_DN);
    let diff = |i: usize| f64::from(frame.pixels[i]) - f64::from(background.pixels[i]);
    let mut seeds: Vec<usize> = (0..frame.pixels.len())
        .filter(|&i| diff(i) > threshold)
        .collect();
    let mut blobs = Vec::new();
    let mut in_blob = vec![false; frame.pixels.len()];
    // Connected (8-neighbour) pixels above half the threshold.
    let low = threshold / 2.0;
    while let Some(seed) = seeds.pop() {
        if in_blob[seed] {
            continue;
        }
        in_blob[seed] = true;
        let mut stack = vec![seed];
        let mut blob = Blob {
            pixels: Vec::new(),
            light: 0.0,
        };
        while let Some(i) = stack.pop() {
            blob.pixels.push(i);
            blob.light += diff(i);
            let (x, y) = ((i % w) as isize, (i / w) as isize);
            for (dx, dy) in [
                (-1, -1),
                (0, -1),
                (1, -1),
                (-1, 0),
                (1, 0),
                (-1, 1),
                (0, 1),
                (1, 1),
            ] {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w as isize || ny >= frame.height as isize {
                    continue;
                }
                let j = ny as usize * w + nx as usize;
                if !in_blob[j] && diff(j) > low {
                    in_blob[j] = true;
                    stack.push(j);
                }
            }
        }
        // A lone hot pixel is noise, not a spot.
        if blob.pixels.len() >= 3 {
            blobs.push(blob);
        }
    }
    blobs.sort_by(|a, b| b.light.total_cmp(&a.light));
    let Some(main) = blobs.first() else {
        return Err(SpotError::NoSpot);
    };
    let centroid_of = |b: &Blob| centroid(b, frame, background, low, noise).0;
    if let Some(second) = blobs
        .get(1)
        .filter(|s| s.light >= SECOND_SPOT_RATIO * main.light)
    {
        return Err(SpotError::TwoSpots {
            at: [centroid_of(main), centroid_of(second)],
        });
    }
    let (image_px, sigma_px) = centroid(main, frame, background, low, noise);
    Ok(SpotMeasurement {
        image_px,
        sigma_px,
        pixels: main.pixels.len(),
        saturated: main
            .pixels
            .iter()
            .filter(|&&i| frame.pixels[i] == 255)
            .count(),
        reflections: blobs.len() - 1,
    })
}

/// Intensity-weighted centroid over the blob's bounding box (+2 px) and
/// its 1-σ error from `noise` DN per pixel. The difference is
/// flat-fielded by the background (divided by the print's reflectance
/// relative to white paper, at most 10×), so a spot half on a printed
/// line is not pulled off it, and clipped at the paper's saturation
/// level: saturated pixels all weigh the same, a symmetric profile.
fn centroid(
    b: &Blob,
    frame: &GrayImage,
    background: &GrayImage,
    floor: f64,
    noise: f64,
) -> ([f64; 2], f64) {
    let w = frame.width;
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for &i in &b.pixels {
        let (x, y) = (i % w, i / w);
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
    }
    let (x0, y0) = (x0.saturating_sub(2), y0.saturating_sub(2));
    let (x1, y1) = ((x1 + 2).min(w - 1), (y1 + 2).min(frame.height - 1));
    let at = |img: &GrayImage, x: usize, y: usize| f64::from(img.pixels[y * w + x]);
    let paper = (y0..=y1)
        .flat_map(|y| (x0..=x1).map(move |x| (x, y)))
        .map(|(x, y)| at(background, x, y))
        .fold(1.0, f64::max);
    let clip = 255.0 - paper;
    let (mut sw, mut sx, mut sy, mut sg2) = (0.0, 0.0, 0.0, Vec::new());
    for y in y0..=y1 {
        for x in x0..=x1 {
            let gain = paper / at(background, x, y).max(paper / 10.0);
            let f = if at(frame, x, y) >= 255.0 {
                clip
            } else {
                ((at(frame, x, y) - at(background, x, y)) * gain).min(clip)
            };
            let wgt = (f - floor).max(0.0);
            if wgt > 0.0 {
                sw += wgt;
                sx += wgt * x as f64;
                sy += wgt * y as f64;
                sg2.push((x, y, gain));
            }
        }
    }
    let c = [sx / sw, sy / sw];
    let (mut vx, mut vy) = (0.0, 0.0);
    for (x, y, g) in sg2 {
        vx += (g * (x as f64 - c[0])).powi(2);
        vy += (g * (y as f64 - c[1])).powi(2);
    }
    (c, noise * vx.max(vy).sqrt() / sw)
}

#[cfg(test)]
mod tests;
