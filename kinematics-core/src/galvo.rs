//! Two-mirror galvo kinematics and the DAC mapping (SPEC §4.5).
//!
//! The X mirror comes first, the Y mirror `e` after it, the board `d` after
//! the Y mirror; a mechanical rotation θ deflects the beam by 2θ. Exact
//! mapping with the pincushion term:
//! `y = d·tan(2θy)`, `x = (√(d² + y²) + e)·tan(2θx)`; the inverse solves y
//! first: `θy = atan(y / d) / 2`, `θx = atan(x / (√(d² + y²) + e)) / 2`.
//! Board x/y are the board frame's (mm), with the galvo axis through Q.
//!
//! Generic over [`Real`](crate::real::Real): `f64` is the reference, `f32` the per-sample path
//! for the Cortex-M4F (held to the `f64` one within 0.001 mm over the ±12.5°
//! field by the tests). DAC code ↔ mechanical angle is linear per axis,
//! `code = round(offset_code + codes_per_rad · θ)`, clamped to 0..=4095
//! with the clamp reported.

mod model;
mod sample_map;
#[cfg(test)]
mod tests;

pub use model::{
    DAC_MAX_CODE, DAC_MID_CODE, DEFAULT_D_MM, DEFAULT_E_MM, DEFAULT_HALF_RANGE_DEG, DacAxis,
    DacCode, DacCodes, Galvo, GalvoGeometry, MirrorAngles,
};
pub use sample_map::{SampleMap, atan_f32};
