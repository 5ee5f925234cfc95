//! The saved form of the settings: a versioned, CRC-checked record of
//! (parameter id, value) entries.
//!
//! Layout of version 3 (all fields little-endian):
//!
//! | bytes              | field                                          |
//! |--------------------|------------------------------------------------|
//! | 0..4               | magic `LPS1`                                   |
//! | 4..6               | version, u16: 3                                |
//! | 6..8               | entry count n, u16                             |
//! | 8..8+10n           | n entries: parameter id u16, value f64; ids strictly ascending |
//! | 8+10n..12+10n      | CRC-32 of bytes 0..8+10n                       |
//!
//! A record is exactly these bytes: its length must match its count, so a
//! corrupted count cannot move where the checksum is read. Values are in
//! the parameter's unit, encoded as [`Settings::get`] returns them.
//!
//! Loading skips entries whose id this build has no parameter for (and
//! counts them), leaves parameters without an entry at their defaults (and
//! counts them), and checks every value as `set` would: adding, removing or
//! compiling out a parameter never changes how the others are stored or
//! read. Records of version 2 (positional, written before parameters had
//! ids) still load, through `legacy.rs`.

use super::legacy;
use super::params::param_by_id;
use super::spec::{ParamSpec, check_value};
use super::{PARAMS, Settings};

/// Version of the record framing. Parameters come and go without a new
/// version (they are keyed by id); bump it only when the framing changes.
pub const RECORD_VERSION: u16 = 3;
/// Record magic (the same for every version).
pub(super) const RECORD_MAGIC: [u8; 4] = *b"LPS1";
/// Bytes before the first entry: magic, version, count.
pub(super) const HEADER_LEN: usize = 8;
/// Bytes of one entry: id, value.
const ENTRY_LEN: usize = 2 + 8;
/// Bytes of the checksum at the end.
pub(super) const CRC_LEN: usize = 4;

/// Bytes of a record of `entries` entries.
pub const fn record_len(entries: usize) -> usize {
    HEADER_LEN + ENTRY_LEN * entries + CRC_LEN
}

/// Bytes of the record this build writes (one entry per parameter).
pub const RECORD_LEN: usize = record_len(PARAMS.len());
/// The most entries a record may have to be loaded by this build: room for
/// records of later builds with more parameters (their unknown entries are
/// skipped).
pub const MAX_RECORD_ENTRIES: usize = 100;
/// Bytes of the longest record this build loads, of either version: the
/// size of a buffer to load a record into.
pub const MAX_RECORD_LEN: usize = record_len(MAX_RECORD_ENTRIES);

const _: () = assert!(PARAMS.len() <= MAX_RECORD_ENTRIES && legacy::MAX_LEN <= MAX_RECORD_LEN);

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

impl Settings {
    /// Serialises into the versioned, checksummed record.
    pub fn to_record(&self) -> [u8; RECORD_LEN] {
        let mut out = [0u8; RECORD_LEN];
        encode(PARAMS, self, &mut out);
        out
    }

    /// Parses a record; every value goes through the checks of
    /// [`Settings::set`], so a record can never load values the command
    /// line would refuse. See [`Settings::load_record`].
    pub fn from_record(bytes: &[u8]) -> Result<Self, RecordError> {
        Self::load_record(bytes).map(|loaded| loaded.settings)
    }

    /// Parses a record of either version (exactly `bytes`), counting the
    /// entries it skipped and the parameters it left at their defaults.
    pub fn load_record(bytes: &[u8]) -> Result<LoadedRecord, RecordError> {
        decode(PARAMS, bytes)
    }
}

/// Writes `settings` as a record of `table`'s parameters (ascending ids)
/// into the start of `out`; returns its length, [`record_len`] of
/// `table.len()` (`out` must have room for it).
pub(super) fn encode(table: &[ParamSpec], settings: &Settings, out: &mut [u8]) -> usize {
    let mut w = Cursor { buf: out, at: 0 };
    w.put(&RECORD_MAGIC);
    w.put(&RECORD_VERSION.to_le_bytes());
    w.put(&(table.len() as u16).to_le_bytes());
    for p in table {
        w.put(&p.id.to_le_bytes());
        w.put(&settings.get(p).to_le_bytes());
    }
    let body = w.at;
    let crc = crc32(w.buf.get(..body).unwrap_or(&[]));
    w.put(&crc.to_le_bytes());
    w.at
}

/// Parses a record of either version against `table`.
pub(super) fn decode(table: &[ParamSpec], bytes: &[u8]) -> Result<LoadedRecord, RecordError> {
    if bytes.len() < HEADER_LEN || bytes.get(..4) != Some(&RECORD_MAGIC[..]) {
        return Err(RecordError::Missing);
    }
    let field = |at: usize| bytes.get(at..at + 2).and_then(le_u16).unwrap_or(0);
    let (version, count) = (field(4), usize::from(field(6)));
    match version {
        RECORD_VERSION => decode_entries(table, bytes, count),
        legacy::VERSION => legacy::decode(table, bytes, count),
        other => Err(RecordError::WrongVersion(other)),
    }
}

/// The entries of a version-3 record of `count` entries.
fn decode_entries(
    table: &[ParamSpec],
    bytes: &[u8],
    count: usize,
) -> Result<LoadedRecord, RecordError> {
    let body = checked_body(bytes, record_len(count))?;
    let mut loading = Loading::new(table);
    let mut last_id = None;
    let entries = body.get(HEADER_LEN..).unwrap_or(&[]);
    for entry in entries.chunks_exact(ENTRY_LEN) {
        let (id, value) = entry.split_at(2);
        let id = le_u16(id).ok_or(RecordError::Corrupt)?;
        // Ascending ids: one encoding per settings, no id twice.
        if last_id.is_some_and(|last| id <= last) {
            return Err(RecordError::Invalid);
        }
        last_id = Some(id);
        loading.entry(id, le_f64(value).ok_or(RecordError::Corrupt)?)?;
    }
    loading.finish(RecordLayout::IdKeyed)
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

/// Length of the record at the start of `bytes` when it is complete and its
/// checksum matches, whatever its version (the length comes from its own
/// count); `None` for anything else. Tells a record an earlier firmware
/// wrote straight into flash from erased or partly written flash.
pub fn intact_record_len(bytes: &[u8]) -> Option<usize> {
    if bytes.get(..4)? != RECORD_MAGIC {
        return None;
    }
    let version = le_u16(bytes.get(4..6)?)?;
    let count = usize::from(le_u16(bytes.get(6..8)?)?);
    let len = match version {
        RECORD_VERSION => record_len(count),
        _ => legacy::len(count),
    };
    checked_body(bytes.get(..len)?, len).ok().map(|_| len)
}

/// A little-endian u16 from exactly two bytes.
fn le_u16(bytes: &[u8]) -> Option<u16> {
    Some(u16::from_le_bytes(bytes.try_into().ok()?))
}

/// A little-endian f64 from exactly eight bytes.
pub(super) fn le_f64(bytes: &[u8]) -> Option<f64> {
    Some(f64::from_le_bytes(bytes.try_into().ok()?))
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
