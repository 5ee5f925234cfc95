//! The virtual camera: renders what a camera sees of the printed target
//! (perspective, intrinsics, radial distortion, vignetting, exposure,
//! shot and read noise) with laser spots as blurred, possibly saturated
//! blobs at the board points where they really land.

use crate::camera::Camera;
use crate::image::GrayImage;
use crate::noise::Noise;
use crate::target::TargetLayout;

/// Sub-samples per pixel along each axis (area sampling of the print).
const SUPERSAMPLE: usize = 3;

/// Exposure and sensor noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exposure {
    /// Grey level of white paper at the image centre, DN (0..255).
    pub paper_dn: f64,
    /// Relative brightness loss at the image corner (0.2 = 20 % darker).
    pub vignetting: f64,
    /// Read noise, DN RMS.
    pub read_noise_dn: f64,
    /// Sensor gain, photo-electrons per DN (shot noise: variance = level / gain).
    pub electrons_per_dn: f64,
}

impl Default for Exposure {
    /// A webcam in room light: paper at 185 DN, 15 % vignetting, 1.5 DN
    /// read noise, 4 e⁻/DN (≈ 7 DN RMS shot noise on white paper).
    fn default() -> Self {
        Self {
            paper_dn: 185.0,
            vignetting: 0.15,
            read_noise_dn: 1.5,
            electrons_per_dn: 4.0,
        }
    }
}

/// A laser spot on the board: a Gaussian of irradiance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaserSpot {
    /// Where the beam hits the board, mm.
    pub board_mm: [f64; 2],
    /// Standard deviation of the spot's irradiance profile, mm.
    pub sigma_mm: f64,
    /// Peak brightness added on white paper, DN (above ~70 the core saturates).
    pub peak_dn: f64,
}

impl LaserSpot {
    /// A 5 mW red pointer spot (σ 0.6 mm), bright enough to saturate its core.
    pub fn at(board_mm: [f64; 2]) -> Self {
        Self {
            board_mm,
            sigma_mm: 0.6,
            peak_dn: 400.0,
        }
    }
}

/// The noise-free image of the board (reused for every frame of one set-up).
#[derive(Debug, Clone)]
pub struct Scene {
    levels: Vec<f32>,
}

/// A camera looking at a printed target.
#[derive(Debug, Clone)]
pub struct VirtualCamera {
    /// Where the camera is and how it images.
    pub camera: Camera,
    /// The printed board.
    pub layout: TargetLayout,
    /// Exposure and noise.
    pub exposure: Exposure,
}

impl VirtualCamera {
    /// Brightness factor of pixel `p` from vignetting.
    fn vignette(&self, p: [f64; 2]) -> f64 {
        let c = &self.camera;
        let r2 = ((p[0] - c.intrinsics.cx) / (c.width as f64 / 2.0)).powi(2)
            + ((p[1] - c.intrinsics.cy) / (c.height as f64 / 2.0)).powi(2);
        1.0 - self.exposure.vignetting * r2 / 2.0
    }

    /// Sub-sample positions of pixel (x, y).
    fn subsamples(x: usize, y: usize) -> impl Iterator<Item = [f64; 2]> {
        let s = SUPERSAMPLE as f64;
        (0..SUPERSAMPLE * SUPERSAMPLE).map(move |k| {
            let (i, j) = ((k % SUPERSAMPLE) as f64, (k / SUPERSAMPLE) as f64);
            [
                x as f64 - 0.5 + (i + 0.5) / s,
                y as f64 - 0.5 + (j + 0.5) / s,
            ]
        })
    }

    /// The noise-free board image (outside the board: a dark wall).
    pub fn scene(&self) -> Scene {
        let (w, h) = (self.camera.width, self.camera.height);
        let [x0, y0, x1, y1] = self.layout.extent_mm;
        let n = (SUPERSAMPLE * SUPERSAMPLE) as f64;
        let mut levels = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let sum: f64 = Self::subsamples(x, y)
                    .map(|p| match self.camera.board_point(p) {
                        Some(b) if (x0..=x1).contains(&b[0]) && (y0..=y1).contains(&b[1]) => {
                            self.layout.reflectance(b)
                        }
                        _ => 0.25,
                    })
                    .sum();
                levels.push(
                    (sum / n * self.exposure.paper_dn * self.vignette([x as f64, y as f64])) as f32,
                );
            }
        }
        Scene { levels }
    }

    /// One exposure of `scene` with `spots` lit, noise drawn from `seed`.
    pub fn frame(&self, scene: &Scene, spots: &[LaserSpot], seed: u64) -> GrayImage {
        let (w, h) = (self.camera.width, self.camera.height);
        let mut levels: Vec<f64> = scene.levels.iter().map(|&v| f64::from(v)).collect();
        for spot in spots {
            self.add_spot(&mut levels, spot);
        }
        let mut noise = Noise::new(seed);
        let e = &self.exposure;
        let pixels = levels
            .iter()
            .map(|&v| {
                let sigma = (e.read_noise_dn.powi(2) + v.max(0.0) / e.electrons_per_dn).sqrt();
                (v + sigma * noise.normal()).round().clamp(0.0, 255.0) as u8
            })
            .collect();
        GrayImage {
            width: w,
            height: h,
            pixels,
        }
    }

    /// Adds the spot's light (scattered by the paper, so scaled by its
    /// reflectance) over the pixels it covers.
    fn add_spot(&self, levels: &mut [f64], spot: &LaserSpot) {
        let reach = 5.0 * spot.sigma_mm;
        let [bx, by] = spot.board_mm;
        let corners = [
            [bx - reach, by - reach],
            [bx + reach, by - reach],
            [bx + reach, by + reach],
            [bx - reach, by + reach],
        ];
        let Some(px) = corners
            .iter()
            .map(|c| self.camera.project(*c))
            .collect::<Option<Vec<_>>>()
        else {
            return;
        };
        let (w, h) = (self.camera.width, self.camera.height);
        let lo = |k: usize| {
            px.iter()
                .map(|p| p[k])
                .fold(f64::INFINITY, f64::min)
                .floor()
                - 1.0
        };
        let hi = |k: usize| {
            px.iter()
                .map(|p| p[k])
                .fold(f64::NEG_INFINITY, f64::max)
                .ceil()
                + 1.0
        };
        let clampi = |v: f64, n: usize| v.clamp(0.0, n as f64) as usize;
        let n = (SUPERSAMPLE * SUPERSAMPLE) as f64;
        for y in clampi(lo(1), h)..clampi(hi(1), h) {
            for x in clampi(lo(0), w)..clampi(hi(0), w) {
                let sum: f64 = Self::subsamples(x, y)
                    .filter_map(|p| self.camera.board_point(p))
                    .map(|b| {
                        let r2 = (b[0] - bx).powi(2) + (b[1] - by).powi(2);
                        (-r2 / (2.0 * spot.sigma_mm.powi(2))).exp() * self.layout.reflectance(b)
                    })
                    .sum();
                if let Some(v) = levels.get_mut(y * w + x) {
                    *v += spot.peak_dn * sum / n;
                }
            }
        }
    }

    /// The mean of `n` exposures (different noise) of `scene` with `spots` lit.
    pub fn averaged_frame(
        &self,
        scene: &Scene,
        spots: &[LaserSpot],
        n: usize,
        seed: u64,
    ) -> GrayImage {
        let frames: Vec<GrayImage> = (0..n.max(1) as u64)
            .map(|k| self.frame(scene, spots, seed.wrapping_mul(31).wrapping_add(k)))
            .collect();
        GrayImage::mean(&frames).unwrap_or_else(|_| self.frame(scene, spots, seed))
    }

    /// Scene and one frame in one call.
    pub fn render(&self, spots: &[LaserSpot], seed: u64) -> GrayImage {
        self.frame(&self.scene(), spots, seed)
    }
}
