//! What loading a saved record of either version shares: the framing's
//! sizes, the checksum, what loading gives ([`LoadedRecord`]) or why it
//! failed ([`RecordError`]), and the value-by-value loader ([`Loading`])
//! both layouts go through (`record.rs`: version 3, `legacy.rs`: version 2).

use super::params::param_by_id;
use super::spec::{ParamSpec, check_value};
use super::values::Settings;

/// Bytes before the first run: magic, version, length.
pub(super) const HEADER_LEN: usize = 8;
/// Bytes of one value.
pub(super) const VALUE_LEN: usize = 8;
/// Bytes of the checksum at the end.
pub(super) const CRC_LEN: usize = 4;

/// Why a saved record was not loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RecordError {
    /// Too short or wrong magic: nothing saved yet.
    Missing,
    /// A version this firmware cannot read.
    WrongVersion(u16),
    /// Checksum or length mismatch.
    Corrupt,
    /// A value is out of range, or the entries are not in the written form.
    Invalid,
}

/// How a loaded record was laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RecordLayout {
    /// Version 3: (id, value) entries.
    IdKeyed,
    /// Version 2: values by position in the parameter table of that time.
    Positional,
}

/// A record that loaded, and what loading it had to make up for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadedRecord {
    /// The settings it holds.
    pub settings: Settings,
    /// Its layout (a positional one is migrated by the next `save`).
    pub layout: RecordLayout,
    /// Entries skipped because this build has no parameter with their id.
    pub unknown: usize,
    /// Parameters it has no entry for, left at their defaults.
    pub defaulted: usize,
}

impl LoadedRecord {
    /// Whether saving the loaded settings writes the same record again
    /// (an id-keyed record with exactly this build's parameters).
    pub fn is_exact(&self) -> bool {
        self.layout == RecordLayout::IdKeyed && self.unknown == 0 && self.defaulted == 0
    }
}

/// Everything before the checksum, when `bytes` is exactly `len` bytes
/// long and its checksum matches.
pub(super) fn checked_body(bytes: &[u8], len: usize) -> Result<&[u8], RecordError> {
    if bytes.len() != len {
        return Err(RecordError::Corrupt);
    }
    let (body, crc) = bytes
        .split_at_checked(len.saturating_sub(CRC_LEN))
        .ok_or(RecordError::Corrupt)?;
    if crc32(body).to_le_bytes()[..] != *crc {
        return Err(RecordError::Corrupt);
    }
    Ok(body)
}

/// Settings being loaded from a record, value by value.
pub(super) struct Loading<'t> {
    table: &'t [ParamSpec],
    settings: Settings,
    known: usize,
    unknown: usize,
}

impl<'t> Loading<'t> {
    /// Starts from the defaults.
    pub(super) fn new(table: &'t [ParamSpec]) -> Self {
        Self {
            table,
            settings: Settings::default(),
            known: 0,
            unknown: 0,
        }
    }

    /// Loads the value of parameter `id` (each id at most once), or counts
    /// it as unknown when `table` has no such parameter.
    pub(super) fn entry(&mut self, id: u16, value: f64) -> Result<(), RecordError> {
        let Some(param) = param_by_id(self.table, id) else {
            self.unknown += 1;
            return Ok(());
        };
        check_value(param, value).map_err(|_| RecordError::Invalid)?;
        self.settings.apply(param, value);
        // Only the encoding `to_record` writes loads (e.g. not −0 for an
        // id), so a loaded record re-saves byte for byte.
        if self.settings.get(param).to_bits() != value.to_bits() {
            return Err(RecordError::Invalid);
        }
        self.known += 1;
        Ok(())
    }

    /// The loaded settings, once the rules between parameters hold for
    /// them as a whole.
    pub(super) fn finish(self, layout: RecordLayout) -> Result<LoadedRecord, RecordError> {
        self.settings.validate().map_err(|_| RecordError::Invalid)?;
        Ok(LoadedRecord {
            settings: self.settings,
            layout,
            unknown: self.unknown,
            defaulted: self.table.len().saturating_sub(self.known),
        })
    }
}

/// A little-endian f64 from exactly eight bytes.
pub(super) fn le_f64(bytes: &[u8]) -> Option<f64> {
    Some(f64::from_le_bytes(bytes.try_into().ok()?))
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
