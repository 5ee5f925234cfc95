//! The saved form of the settings: a versioned, CRC-checked record.

use super::params::check_value;
use super::{PARAMS, Settings};

/// Saved-record layout version; bump when [`PARAMS`] changes.
pub const RECORD_VERSION: u16 = 2;
/// Record magic.
const RECORD_MAGIC: [u8; 4] = *b"LPS1";
/// Bytes of a saved record: magic, version, count, values, CRC-32.
pub const RECORD_LEN: usize = 4 + 2 + 2 + 8 * PARAMS.len() + 4;

/// Why a saved record was not loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RecordError {
    /// Too short or wrong magic: nothing saved yet.
    Missing,
    /// Saved by another firmware version (layout differs).
    WrongVersion(u16),
    /// Checksum mismatch.
    Corrupt,
    /// A value is out of range.
    Invalid,
}

impl Settings {
    /// Serialises into the versioned, checksummed record.
    pub fn to_record(&self) -> [u8; RECORD_LEN] {
        let mut out = [0u8; RECORD_LEN];
        let mut w = Cursor {
            buf: &mut out,
            at: 0,
        };
        w.put(&RECORD_MAGIC);
        w.put(&RECORD_VERSION.to_le_bytes());
        w.put(&(PARAMS.len() as u16).to_le_bytes());
        for p in PARAMS {
            w.put(&self.get(p).to_le_bytes());
        }
        let body = RECORD_LEN - 4;
        let crc = crc32(out.get(..body).unwrap_or(&[]));
        if let Some(tail) = out.get_mut(body..) {
            tail.copy_from_slice(&crc.to_le_bytes());
        }
        out
    }

    /// Parses a record; every value goes through [`Settings::set`], so a
    /// record can never load values the command line would refuse.
    pub fn from_record(bytes: &[u8]) -> Result<Self, RecordError> {
        if bytes.len() < 8 || bytes.get(..4) != Some(&RECORD_MAGIC[..]) {
            return Err(RecordError::Missing);
        }
        let field = |at: usize| {
            u16::from_le_bytes([
                bytes.get(at).copied().unwrap_or(0),
                bytes.get(at + 1).copied().unwrap_or(0),
            ])
        };
        let (version, count) = (field(4), field(6));
        if version != RECORD_VERSION || usize::from(count) != PARAMS.len() {
            return Err(RecordError::WrongVersion(version));
        }
        let record = bytes.get(..RECORD_LEN).ok_or(RecordError::Corrupt)?;
        let (body, crc) = record.split_at(RECORD_LEN - 4);
        if crc32(body).to_le_bytes() != crc {
            return Err(RecordError::Corrupt);
        }
        let mut settings = Settings::default();
        for (i, p) in PARAMS.iter().enumerate() {
            let at = 8 + 8 * i;
            let mut le = [0u8; 8];
            le.copy_from_slice(body.get(at..at + 8).ok_or(RecordError::Corrupt)?);
            let value = f64::from_le_bytes(le);
            check_value(p, value).map_err(|_| RecordError::Invalid)?;
            settings.apply(p, value);
            // Only the encoding `to_record` writes loads (e.g. not −0 for
            // an id), so a loaded record re-saves byte for byte.
            if settings.get(p).to_bits() != value.to_bits() {
                return Err(RecordError::Invalid);
            }
        }
        // Cross-parameter rules apply to the loaded set as a whole.
        settings.validate().map_err(|_| RecordError::Invalid)?;
        Ok(settings)
    }
}

/// Length of the record at the start of `bytes` when it is complete and its
/// checksum matches, whatever its version (the length comes from its own
/// parameter count); `None` for anything else. Tells a record written by an
/// older firmware straight into flash from erased or partly written flash.
pub fn intact_record_len(bytes: &[u8]) -> Option<usize> {
    if bytes.get(..4)? != RECORD_MAGIC {
        return None;
    }
    let count = u16::from_le_bytes([*bytes.get(6)?, *bytes.get(7)?]);
    let len = 4 + 2 + 2 + 8 * usize::from(count) + 4;
    let (body, crc) = bytes.get(..len)?.split_at(len - 4);
    (crc32(body).to_le_bytes() == crc).then_some(len)
}

struct Cursor<'a> {
    buf: &'a mut [u8],
    at: usize,
}

impl Cursor<'_> {
    fn put(&mut self, bytes: &[u8]) {
        if let Some(dst) = self.buf.get_mut(self.at..self.at + bytes.len()) {
            dst.copy_from_slice(bytes);
        }
        self.at += bytes.len();
    }
}

/// CRC-32 (IEEE 802.3, reflected, init and xor-out 0xFFFFFFFF).
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            let mask = (crc & 1).wrapping_neg();
            crc = (crc >> 1) ^ (0xEDB8_8320 & mask);
        }
    }
    !crc
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::{AxisSettings, LaserMode};

    #[test]
    fn crc32_matches_the_standard_check_value() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    #[test]
    fn record_round_trips_every_parameter() {
        let mut err_dy = [0.0; 6];
        err_dy[5] = -7.5e-6;
        let s = Settings {
            oq_cm: 31.25,
            err_dx: [0.1, -0.002, 0.003, 1e-5, -2e-5, 3e-6],
            err_dy,
            laser_mode: LaserMode::Dwell,
            pitch: AxisSettings {
                direction: -1,
                ..Settings::default().pitch
            },
            grid_cols: 10,
            ..Settings::default()
        };
        let record = s.to_record();
        assert_eq!(Settings::from_record(&record), Ok(s));
    }

    #[test]
    fn intact_record_len_accepts_only_whole_checksummed_records() {
        let record = Settings::default().to_record();
        let mut flash = [0xFFu8; RECORD_LEN + 64];
        flash[..RECORD_LEN].copy_from_slice(&record);
        assert_eq!(intact_record_len(&flash), Some(RECORD_LEN));
        // Cut short (a write interrupted at any byte) or truncated input.
        for cut in 0..RECORD_LEN {
            let mut partial = [0xFFu8; RECORD_LEN + 64];
            partial[..cut].copy_from_slice(&record[..cut]);
            assert_eq!(intact_record_len(&partial), None, "cut at {cut}");
            assert_eq!(intact_record_len(&record[..cut]), None);
        }
        // Any single flipped bit.
        for bit in 0..RECORD_LEN * 8 {
            let mut flipped = record;
            flipped[bit / 8] ^= 1 << (bit % 8);
            assert_eq!(intact_record_len(&flipped), None, "bit {bit}");
        }
    }

    #[test]
    fn corrupt_old_or_missing_records_are_refused() {
        let record = Settings::default().to_record();
        assert_eq!(
            Settings::from_record(&[0xff; RECORD_LEN]),
            Err(RecordError::Missing)
        );
        assert_eq!(Settings::from_record(&[]), Err(RecordError::Missing));
        let mut flipped = record;
        flipped[20] ^= 0x10;
        assert_eq!(Settings::from_record(&flipped), Err(RecordError::Corrupt));
        let mut old = record;
        old[4] = 0;
        assert!(matches!(
            Settings::from_record(&old),
            Err(RecordError::WrongVersion(0))
        ));
        // A well-formed record with an out-of-range value (checksum fixed up).
        let bad = Settings {
            dwell_ms: -5.0,
            ..Settings::default()
        };
        assert_eq!(
            Settings::from_record(&bad.to_record()),
            Err(RecordError::Invalid)
        );
    }

    #[test]
    fn only_the_written_encoding_loads() {
        // −0 where an id, a mode or the planner is stored: check_value
        // takes it (−0 == 0), but it would load as +0 and re-save
        // differently. Found by the settings_record fuzz target's property
        // (tests/fuzz/artifacts/settings_record/).
        for name in ["yaw.id", "laser.mode", "galvo.planner"] {
            let Some(at) = PARAMS.iter().position(|p| p.name == name) else {
                continue;
            };
            let mut record = Settings::default().to_record();
            let field = 8 + 8 * at;
            record[field..field + 8].copy_from_slice(&(-0.0f64).to_le_bytes());
            let body = RECORD_LEN - 4;
            let crc = crc32(&record[..body]);
            record[body..].copy_from_slice(&crc.to_le_bytes());
            assert_eq!(
                Settings::from_record(&record),
                Err(RecordError::Invalid),
                "{name} = -0"
            );
        }
        // −0 in a real-valued parameter is stored as is and loads.
        let s = Settings {
            x_offset_cm: -0.0,
            ..Settings::default()
        };
        let loaded = Settings::from_record(&s.to_record()).unwrap();
        assert_eq!(loaded.x_offset_cm.to_bits(), (-0.0f64).to_bits());
    }
}
