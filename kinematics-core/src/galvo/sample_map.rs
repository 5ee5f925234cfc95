//! The per-sample galvo map: board point or mirror angles → DAC codes in
//! `f32` on the FPU, checked once when built.
//!
//! Per call: one multiply for `y / d`, one `VSQRT`, one `VDIV`, two
//! [`atan_f32`] (a range reduction and a degree-9 odd polynomial, no
//! table, no `f64`) and two direct conversions. libm's `atanf` (≈ 80 M4
//! instructions with its five ranges) was the dearest part of a marking
//! sample; the polynomial's error (< 1e-7 rad, test) is below 1/1000 DAC
//! LSB, so the codes stay within ½ LSB of the `f64` reference over the
//! whole field (`f32_codes_within_half_an_lsb_of_f64_over_the_field`).

use super::model::{DacAxis, DacCodes, Galvo, round_to_code};
use crate::error::Error;

/// tan(π/8): below it the polynomial applies directly.
const TAN_PI_8: f32 = 0.414_213_57;
/// tan(3π/8): above it `atan(t) = π/2 − atan(1/t)`.
const TAN_3PI_8: f32 = 2.414_213_6;
/// `atan(u)/u ≈ P(u²)` on `|u| ≤ tan(π/8)`: the interpolant of
/// `atan(√z)/√z` at the five Chebyshev nodes of `z ∈ [0, tan²(π/8)]`
/// (computed with 40-digit arithmetic; exact-arithmetic error of
/// `u·P(u²)` below 7e-9 rad), lowest power first.
const ATAN_P: [f32; 5] = [
    0.999_999_98,
    -0.333_327_86,
    0.199_740_82,
    -0.138_484_9,
    0.079_762_92,
];

/// Arc tangent of `t` (rad) in `f32` without `f64` or tables: `|t|`
/// reduced to `|u| ≤ tan(π/8)` (`u = t`, `(t − 1)/(t + 1)` with π/4 added,
/// or `−1/t` with π/2 added), then `u·P(u²)`. Absolute error below 2e-7
/// rad over all `t` (test against the `f64` `atan`); odd; ±π/2 at ±∞,
/// NaN for NaN.
#[inline]
pub fn atan_f32(t: f32) -> f32 {
    let a = f32::from_bits(t.to_bits() & 0x7fff_ffff);
    let (base, u) = if a <= TAN_PI_8 {
        (0.0, a)
    } else if a <= TAN_3PI_8 {
        (core::f32::consts::FRAC_PI_4, (a - 1.0) / (a + 1.0))
    } else {
        // Also NaN, which stays NaN.
        (core::f32::consts::FRAC_PI_2, -1.0 / a)
    };
    let z = u * u;
    let [c0, c1, c2, c3, c4] = ATAN_P;
    let p = c0 + z * (c1 + z * (c2 + z * (c3 + z * c4)));
    let r = base + u * p;
    // The sign of t.
    f32::from_bits(r.to_bits() | (t.to_bits() & 0x8000_0000))
}

/// A finite code value rounded half away from zero to a DAC code,
/// saturated to 0..=4095: the code of [`round_to_code`] (tests), in five
/// FPU/ALU instructions instead of its compare chain. For `v ≥ ½`,
/// `v + ½` in `f32` is exact or rounds within its binade's first half
/// unit above a power of two, so its truncation is `⌊v + ½⌋`; below ½
/// the code is 0 (or, under −½, saturated to 0).
#[inline(always)]
fn block_code(v: f32) -> u16 {
    let up = (v + 0.5) as u32;
    let code = if v < 0.5 { 0 } else { up };
    code.min(u32::from(super::model::DAC_MAX_CODE)) as u16
}

/// The per-sample form of a [`Galvo<f32>`]: checked once when built, then
/// board point or mirror angles → DAC codes with no per-call validation
/// and no error plumbing, all in `f32` on the FPU. Its angle → code
/// mapping is [`Galvo::angles_to_codes`] bit for bit; its IK uses
/// [`atan_f32`], so its board → code mapping matches
/// [`Galvo::<f32>::board_to_codes`] except within a hair of a rounding tie
/// (tests) and stays within ½ LSB of the `f64` reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleMap {
    /// 1 / d, 1/mm.
    inv_d: f32,
    d2_mm2: f32,
    e_mm: f32,
    dac_x: DacAxis<f32>,
    dac_y: DacAxis<f32>,
    /// Codes per radian of beam deflection (half the mechanical one), x
    /// and y: the IK's `½·atan` folded into the DAC slope.
    half_slope: [f32; 2],
}

impl SampleMap {
    /// The per-sample map of `galvo`.
    ///
    /// Errors: [`Error::InvalidConfig`] (geometry, or a zero / non-finite
    /// DAC mapping).
    pub fn new(galvo: &Galvo<f32>) -> Result<Self, Error> {
        galvo.geometry.validate()?;
        for dac in [galvo.dac_x, galvo.dac_y] {
            if !dac.codes_per_rad.is_finite()
                || dac.codes_per_rad == 0.0
                || !dac.offset_code.is_finite()
            {
                return Err(Error::InvalidConfig {
                    what: "DAC codes_per_rad must be finite and non-zero",
                });
            }
        }
        let d = galvo.geometry.d_mm;
        Ok(Self {
            inv_d: 1.0 / d,
            d2_mm2: d * d,
            e_mm: galvo.geometry.e_mm,
            dac_x: galvo.dac_x,
            dac_y: galvo.dac_y,
            // Exact: a power-of-two scale.
            half_slope: [
                galvo.dac_x.codes_per_rad * 0.5,
                galvo.dac_y.codes_per_rad * 0.5,
            ],
        })
    }

    /// DAC codes for board point (`x_mm`, `y_mm`); `None` for a
    /// non-finite coordinate.
    #[inline]
    pub fn board_to_codes(&self, x_mm: f32, y_mm: f32) -> Option<DacCodes> {
        if !(x_mm.is_finite() && y_mm.is_finite()) {
            return None;
        }
        // GalvoGeometry::ik: θy = atan(y/d)/2, θx = atan(x/(√(d²+y²)+e))/2.
        let path_mm = crate::real::sqrt_f32(self.d2_mm2 + y_mm * y_mm) + self.e_mm;
        let [sx, sy] = self.half_slope;
        let x = self.dac_x.offset_code + sx * atan_f32(x_mm / path_mm);
        let y = self.dac_y.offset_code + sy * atan_f32(y_mm * self.inv_d);
        Some(DacCodes {
            x: round_to_code(x),
            y: round_to_code(y),
        })
    }

    /// DAC codes for mechanical mirror angles (rad); `None` for a
    /// non-finite angle.
    #[inline]
    pub fn angles_to_codes(&self, x_rad: f32, y_rad: f32) -> Option<DacCodes> {
        let x = self.dac_x.offset_code + self.dac_x.codes_per_rad * x_rad;
        let y = self.dac_y.offset_code + self.dac_y.codes_per_rad * y_rad;
        if !(x.is_finite() && y.is_finite()) {
            return None;
        }
        Some(DacCodes {
            x: round_to_code(x),
            y: round_to_code(y),
        })
    }

    /// The codes `[x, y]` of a block of mirror angles `[θx, θy]` (rad)
    /// into `codes` (up to the shorter of the two); a non-finite angle
    /// repeats the codes before it (`hold` for the first). Returns the
    /// last codes. A concrete loop compiled here, for speed (see
    /// `galvo_planner::blocks`).
    #[inline(never)]
    pub fn angles_block(
        &self,
        angles: &[[f32; 2]],
        codes: &mut [[u16; 2]],
        hold: [u16; 2],
    ) -> [u16; 2] {
        let mut last = hold;
        for (out, &[x_rad, y_rad]) in codes.iter_mut().zip(angles) {
            last = self.angle_codes_or(x_rad, y_rad, last);
            *out = last;
        }
        last
    }

    /// The codes `[x, y]` of mirror angles given per axis, `θx` from `x`
    /// and `θy` from `y` (rad), as [`Self::angles_block`] does for pairs.
    #[inline(never)]
    pub fn axes_block(
        &self,
        x: &[f32],
        y: &[f32],
        codes: &mut [[u16; 2]],
        hold: [u16; 2],
    ) -> [u16; 2] {
        let mut last = hold;
        for ((out, &x_rad), &y_rad) in codes.iter_mut().zip(x).zip(y) {
            last = self.angle_codes_or(x_rad, y_rad, last);
            *out = last;
        }
        last
    }

    /// The codes of mirror angles `θx`, `θy` (rad), or `last` when either
    /// code is not finite (the blocks' per-sample step).
    #[inline(always)]
    fn angle_codes_or(&self, x_rad: f32, y_rad: f32, last: [u16; 2]) -> [u16; 2] {
        let x = self.dac_x.offset_code + self.dac_x.codes_per_rad * x_rad;
        let y = self.dac_y.offset_code + self.dac_y.codes_per_rad * y_rad;
        if x.is_finite() && y.is_finite() {
            [block_code(x), block_code(y)]
        } else {
            last
        }
    }

    /// The codes `[x, y]` of a block of board points `[x, y]` (mm), as
    /// [`Self::angles_block`] does for angles.
    #[inline(never)]
    pub fn board_block(
        &self,
        points_mm: &[[f32; 2]],
        codes: &mut [[u16; 2]],
        hold: [u16; 2],
    ) -> [u16; 2] {
        let mut last = hold;
        let [sx, sy] = self.half_slope;
        for (out, &[x_mm, y_mm]) in codes.iter_mut().zip(points_mm) {
            if x_mm.is_finite() && y_mm.is_finite() {
                // As Self::board_to_codes, operation for operation.
                let path_mm = crate::real::sqrt_f32(self.d2_mm2 + y_mm * y_mm) + self.e_mm;
                let x = self.dac_x.offset_code + sx * atan_f32(x_mm / path_mm);
                let y = self.dac_y.offset_code + sy * atan_f32(y_mm * self.inv_d);
                last = [block_code(x), block_code(y)];
            }
            *out = last;
        }
        last
    }
}

#[cfg(test)]
mod tests;
