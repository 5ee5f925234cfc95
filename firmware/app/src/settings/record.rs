//! The saved form of the settings: a versioned, CRC-checked record of
//! values keyed by parameter id.
//!
//! Layout of version 3 (all fields little-endian):
//!
//! | bytes      | field                                                   |
//! |------------|---------------------------------------------------------|
//! | 0..4       | magic `LPS1`                                            |
//! | 4..6       | version, u16: 3                                         |
//! | 6..8       | length L of the whole record, u16                       |
//! | 8..        | runs: id of the first value u16, value count k u8 (1..=255), k values f64 (ids first, first+1, …) |
//! | ..L-4      | 0–3 zero bytes: the CRC starts on a whole 32-bit word   |
//! | L-4..L     | CRC-32 of bytes 0..L-4                                  |
//!
//! Each value is keyed by its parameter's id; consecutive ids share one run
//! head (3 bytes per run instead of 2 per value keeps the record of 54
//! parameters at 488 bytes: more than 250 saves fill a 128 KiB sector, and
//! two records fit the scaled sectors of the power-cut tests). The length
//! is a whole number of words, as the positional records' always was.
//! Runs are maximal and ascending (the one encoding of a set of values), a
//! record is exactly its length, so a corrupted length cannot move where
//! the checksum is read. Values are in the parameter's unit, as
//! [`Settings::get`] returns them.
//!
//! Loading skips values whose id this build has no parameter for (and
//! counts them), leaves parameters without a value at their defaults (and
//! counts them), and checks every value as `set` would: adding, removing or
//! compiling out a parameter never changes how the others are stored or
//! read. Records of version 2 (positional, written before parameters had
//! ids) still load, through `legacy.rs`.

use super::legacy;
use super::loading::{
    CRC_LEN, HEADER_LEN, LoadedRecord, Loading, RecordError, RecordLayout, VALUE_LEN, checked_body,
    crc32, le_f64,
};
use super::params::PARAMS;
use super::spec::ParamSpec;
use super::values::Settings;

/// Version of the record framing. Parameters come and go without a new
/// version (they are keyed by id); bump it only when the framing changes.
pub const RECORD_VERSION: u16 = 3;
/// Record magic (the same for every version).
pub(super) const RECORD_MAGIC: [u8; 4] = *b"LPS1";
/// Bytes of a run head: first id, value count.
const RUN_HEAD_LEN: usize = 3;
/// Most values in one run.
const MAX_RUN: usize = u8::MAX as usize;
/// The checksum starts at a multiple of this (a 32-bit word).
const WORD: usize = 4;

/// End (exclusive) of the run of `table` (ids ascending) that starts at
/// index `start`: the stretch of consecutive ids, at most [`MAX_RUN`].
const fn run_end(table: &[ParamSpec], start: usize) -> usize {
    let mut end = start + 1;
    while end < table.len()
        && end - start < MAX_RUN
        && table[end].id as usize == table[end - 1].id as usize + 1
    {
        end += 1;
    }
    end
}

/// Bytes of the record of `table`'s parameters (ids ascending).
pub(super) const fn record_len(table: &[ParamSpec]) -> usize {
    let mut len = HEADER_LEN + CRC_LEN;
    let mut start = 0;
    while start < table.len() {
        let end = run_end(table, start);
        len += RUN_HEAD_LEN + VALUE_LEN * (end - start);
        start = end;
    }
    len.next_multiple_of(WORD)
}

/// Bytes of the record this build writes (all its parameters).
pub const RECORD_LEN: usize = record_len(PARAMS);
/// Bytes of the longest record this build loads, of either version (the
/// size of a buffer to load a record into): room for records of later
/// builds with more parameters, whose unknown values are skipped.
pub const MAX_RECORD_LEN: usize = 1024;

const _: () = assert!(RECORD_LEN <= MAX_RECORD_LEN && legacy::MAX_LEN <= MAX_RECORD_LEN);

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

/// Writes `settings` as a record of `table`'s parameters (ids ascending)
/// into the start of `out`; returns its length, `record_len(table)` (`out`
/// must have room for it).
pub(super) fn encode(table: &[ParamSpec], settings: &Settings, out: &mut [u8]) -> usize {
    let mut w = Cursor { buf: out, at: 0 };
    w.put(&RECORD_MAGIC);
    w.put(&RECORD_VERSION.to_le_bytes());
    w.put(&(record_len(table) as u16).to_le_bytes());
    let mut start = 0;
    while start < table.len() {
        let end = run_end(table, start);
        let run = table.get(start..end).unwrap_or(&[]);
        let first = run.first().map_or(0, |p| p.id);
        w.put(&first.to_le_bytes());
        w.put(&[run.len() as u8]);
        for p in run {
            w.put(&settings.get(p).to_le_bytes());
        }
        start = end;
    }
    while !w.at.is_multiple_of(WORD) {
        w.put(&[0]);
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
    match field(4) {
        RECORD_VERSION => decode_runs(table, bytes, usize::from(field(6))),
        legacy::VERSION => legacy::decode(table, bytes, usize::from(field(6))),
        other => Err(RecordError::WrongVersion(other)),
    }
}

/// The runs of a version-3 record of `len` bytes.
fn decode_runs(table: &[ParamSpec], bytes: &[u8], len: usize) -> Result<LoadedRecord, RecordError> {
    let body = checked_body(bytes, len)?;
    let mut runs = body.get(HEADER_LEN..).unwrap_or(&[]);
    let mut loading = Loading::new(table);
    // The id after the previous run, and whether it was full.
    let mut next: Option<(u32, bool)> = None;
    // A run has at least one value: fewer bytes than a word are padding.
    while runs.len() >= WORD {
        let (head, rest) = runs
            .split_at_checked(RUN_HEAD_LEN)
            .ok_or(RecordError::Corrupt)?;
        let (first, count) = match head {
            [lo, hi, count] => (u16::from_le_bytes([*lo, *hi]), usize::from(*count)),
            _ => return Err(RecordError::Corrupt),
        };
        // Ascending, maximal, non-empty runs: one encoding per settings.
        let canonical = count > 0
            && usize::from(first) + count <= usize::from(u16::MAX) + 1
            && next.is_none_or(|(after, full)| {
                u32::from(first) > after || (u32::from(first) == after && full)
            });
        if !canonical {
            return Err(RecordError::Invalid);
        }
        let (values, rest) = rest
            .split_at_checked(VALUE_LEN * count)
            .ok_or(RecordError::Corrupt)?;
        for (id, value) in (first..=u16::MAX).zip(values.chunks_exact(VALUE_LEN)) {
            loading.entry(id, le_f64(value).ok_or(RecordError::Corrupt)?)?;
        }
        next = Some((u32::from(first) + count as u32, count == MAX_RUN));
        runs = rest;
    }
    // The checksum is word-aligned (`checked_body` took `len`), so what is
    // left is exactly the padding.
    if !len.is_multiple_of(WORD) || runs.iter().any(|b| *b != 0) {
        return Err(RecordError::Invalid);
    }
    loading.finish(RecordLayout::IdKeyed)
}

/// Length of the record at the start of `bytes` when it is complete and its
/// checksum matches, whatever its version (the length comes from its own
/// count); `None` for anything else. Tells a record an earlier firmware
/// wrote straight into flash from erased or partly written flash.
pub fn intact_record_len(bytes: &[u8]) -> Option<usize> {
    let len = claimed_record_len(bytes)?;
    checked_body(bytes.get(..len)?, len).ok().map(|_| len)
}

/// The length the record starting with `header` has by its magic, version
/// and length or count field (version 3: its length; any other: the
/// positional layout of its value count), whether or not the rest is there.
pub fn claimed_record_len(header: &[u8]) -> Option<usize> {
    if header.get(..4)? != RECORD_MAGIC {
        return None;
    }
    let version = le_u16(header.get(4..6)?)?;
    let field = usize::from(le_u16(header.get(6..8)?)?);
    Some(match version {
        RECORD_VERSION => field,
        _ => legacy::len(field),
    })
}

/// A little-endian u16 from exactly two bytes.
fn le_u16(bytes: &[u8]) -> Option<u16> {
    Some(u16::from_le_bytes(bytes.try_into().ok()?))
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
