//! Presets (PELCO's 1–255, `preset set|clear|goto`): board points kept in
//! the settings store next to the settings record, one map item each, so a
//! preset set on one actuator is the same spot on every other.
//!
//! Keys of the store's map ([`StoreKey`]): the settings record is key byte
//! `1` (as it always was: a store written before presets reads the same),
//! preset n the two bytes `2, n`. A preset's value is its board point as
//! two little-endian f32, x then y, in **cm** (8 bytes: with the map's
//! 8-byte item header and the 2-byte key, 20 bytes of flash on 4-byte
//! words); a cleared preset is an empty value (a tombstone, written like
//! any item, so clearing is as power-fail safe as setting). 255 presets
//! take 5 KiB of a 128 KiB sector; nothing of them is kept in RAM (a call
//! reads its preset from the store).

use sequential_storage::map::{Key, SerializationError};

use crate::domain::{BOARD_LIMIT_CM, PointCm};

/// Highest preset number (the lowest is 1).
pub const MAX_PRESET: u8 = 255;

/// Bytes of a saved preset's value.
pub(super) const PRESET_VALUE_LEN: usize = 8;

/// Key byte of the settings record.
const RECORD_TAG: u8 = 1;
/// First key byte of a preset (the second is its number).
const PRESET_TAG: u8 = 2;

/// A key of the settings store's map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum StoreKey {
    /// The settings record.
    Record,
    /// Preset n (1–255).
    Preset(u8),
}

impl Key for StoreKey {
    fn serialize_into(&self, buffer: &mut [u8]) -> Result<usize, SerializationError> {
        let bytes: &[u8] = match self {
            StoreKey::Record => &[RECORD_TAG],
            StoreKey::Preset(n) => &[PRESET_TAG, *n],
        };
        buffer
            .get_mut(..bytes.len())
            .ok_or(SerializationError::BufferTooSmall)?
            .copy_from_slice(bytes);
        Ok(bytes.len())
    }

    fn deserialize_from(buffer: &[u8]) -> Result<(Self, usize), SerializationError> {
        match buffer {
            [RECORD_TAG, ..] => Ok((StoreKey::Record, 1)),
            [PRESET_TAG, n, ..] => Ok((StoreKey::Preset(*n), 2)),
            [PRESET_TAG] | [] => Err(SerializationError::BufferTooSmall),
            _ => Err(SerializationError::InvalidFormat),
        }
    }
}

/// The saved value of board point `p` (cm): x, y as f32.
pub(super) fn encode_preset(p: PointCm) -> [u8; PRESET_VALUE_LEN] {
    let mut out = [0u8; PRESET_VALUE_LEN];
    let (x, y) = out.split_at_mut(4);
    x.copy_from_slice(&(p.x_cm as f32).to_le_bytes());
    y.copy_from_slice(&(p.y_cm as f32).to_le_bytes());
    out
}

/// The board point of a saved value, cm; `None` for a cleared preset (an
/// empty value) and for anything that is not a finite point within
/// ±[`BOARD_LIMIT_CM`].
pub(super) fn decode_preset(value: &[u8]) -> Option<PointCm> {
    let [x0, x1, x2, x3, y0, y1, y2, y3] = *value else {
        return None;
    };
    let x = f64::from(f32::from_le_bytes([x0, x1, x2, x3]));
    let y = f64::from(f32::from_le_bytes([y0, y1, y2, y3]));
    let usable = |v: f64| v.is_finite() && v.abs() <= BOARD_LIMIT_CM;
    (usable(x) && usable(y)).then_some(PointCm::new(x, y))
}

/// Whether `n` numbers a preset (1–255).
pub fn is_preset(n: u8) -> bool {
    (1..=MAX_PRESET).contains(&n)
}

/// Whether board point `p` can be saved as a preset: finite, within
/// ±[`BOARD_LIMIT_CM`] (what loading accepts).
pub fn savable(p: PointCm) -> bool {
    decode_preset(&encode_preset(p)).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_key_is_the_byte_it_always_was_and_presets_take_two() {
        let mut buf = [0u8; 4];
        assert_eq!(StoreKey::Record.serialize_into(&mut buf), Ok(1));
        assert_eq!(buf[0], 1, "u8 key 1 of the store before presets");
        assert_eq!(
            StoreKey::deserialize_from(&[1, 9]),
            Ok((StoreKey::Record, 1))
        );
        assert_eq!(StoreKey::Preset(255).serialize_into(&mut buf), Ok(2));
        assert_eq!(buf[..2], [2, 255]);
        assert_eq!(
            StoreKey::deserialize_from(&buf[..2]),
            Ok((StoreKey::Preset(255), 2))
        );
        assert!(StoreKey::deserialize_from(&[2]).is_err());
        assert!(StoreKey::deserialize_from(&[7, 1]).is_err());
        assert!(StoreKey::Preset(1).serialize_into(&mut buf[..1]).is_err());
    }

    #[test]
    fn values_round_trip_in_f32_and_bad_ones_are_no_preset() {
        let p = PointCm::new(12.345, -199.5);
        let back = decode_preset(&encode_preset(p)).unwrap();
        assert!((back.x_cm - p.x_cm).abs() < 1e-5 && (back.y_cm - p.y_cm).abs() < 1e-5);
        assert_eq!(decode_preset(&[]), None, "cleared");
        assert_eq!(decode_preset(&[0; 7]), None);
        assert_eq!(decode_preset(&[0; 9]), None);
        let nan = encode_preset(PointCm::new(f64::NAN, 0.0));
        assert_eq!(decode_preset(&nan), None);
        assert!(!savable(PointCm::new(0.0, 200.5)));
        assert!(!savable(PointCm::new(f64::INFINITY, 0.0)));
        assert!(savable(PointCm::new(-200.0, 200.0)));
        assert!(!is_preset(0) && is_preset(1) && is_preset(255));
    }
}
