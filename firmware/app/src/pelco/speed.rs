//! The speed table: a frame's pan/tilt speed byte to a line-of-sight rate.
//!
//! | speed byte        | rate                              |
//! |-------------------|-----------------------------------|
//! | 0x00              | stop (that axis)                  |
//! | 0x01–0x40         | byte × [`DEG_S_PER_STEP`] (0.5–32 °/s) |
//! | 0x41–0xFE         | as 0x3F (31.5 °/s)                |
//! | 0xFF (turbo)      | [`TURBO_DEG_S`] (40 °/s)          |
//!
//! PELCO-D speeds run to 0x3F, PELCO-P's to 0x40.

/// Rate per speed step, deg/s.
pub const DEG_S_PER_STEP: f32 = 0.5;
/// Rate of the turbo speed byte 0xFF, deg/s.
pub const TURBO_DEG_S: f32 = 40.0;
/// Highest ordinary speed byte (PELCO-P's top speed).
const TOP_STEP: u8 = 0x40;
/// Speed used for the out-of-range bytes 0x41–0xFE (PELCO-D's top).
const D_TOP_STEP: u8 = 0x3F;

/// The rate of speed byte `speed`, deg/s (0 for a stopped axis).
pub fn rate_deg_s(speed: u8) -> f32 {
    match speed {
        0xFF => TURBO_DEG_S,
        0..=TOP_STEP => f32::from(speed) * DEG_S_PER_STEP,
        _ => f32::from(D_TOP_STEP) * DEG_S_PER_STEP,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_rows() {
        assert_eq!(rate_deg_s(0), 0.0);
        assert_eq!(rate_deg_s(1), 0.5);
        assert_eq!(rate_deg_s(0x20), 16.0);
        assert_eq!(rate_deg_s(0x3F), 31.5);
        assert_eq!(rate_deg_s(0x40), 32.0);
        assert_eq!(rate_deg_s(0x80), 31.5);
        assert_eq!(rate_deg_s(0xFF), 40.0);
    }
}
