//! The PELCO port's saved settings (ids 200–209): the device address the
//! port answers, its baud rate and the motion timeout (see `docs/pelco.md`).
//!
//! One more run of 3 values: the record grows from 692 to 720 bytes and a
//! 128 KiB sector holds 179 saves before an erase instead of ≈ 190 (still
//! 35 million saves over the sectors' 100 000 erase cycles); a record
//! saved before them loads with the 3 at their defaults.

/// The baud rates the PELCO port runs at (8N1).
pub const PELCO_BAUDS: [u32; 4] = [2400, 4800, 9600, 19200];

/// The PELCO port's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PelcoSettings {
    /// Device address answered (1–255; PELCO-P sends it minus one).
    pub address: u8,
    /// Baud rate, one of [`PELCO_BAUDS`] (stored as f64).
    pub baud: f64,
    /// Motion stops when no frame arrived for this long, s (0: never, as
    /// on most PTZ heads).
    pub motion_timeout_s: f64,
}

impl Default for PelcoSettings {
    fn default() -> Self {
        Self {
            address: 1,
            baud: 9600.0,
            motion_timeout_s: 0.0,
        }
    }
}

/// Whether `value` is a baud rate the port runs at.
pub(super) fn is_pelco_baud(value: f64) -> bool {
    PELCO_BAUDS.iter().any(|b| f64::from(*b) == value)
}
