//! Records of version 2, written before parameters had ids: magic, version
//! 2, value count u16, the values (f64, little-endian) in the order of that
//! firmware's parameter table, CRC-32 of all that. They load (the next
//! `save` writes the id-keyed layout).

use super::loading::{
    CRC_LEN, HEADER_LEN, LoadedRecord, Loading, RecordError, RecordLayout, VALUE_LEN, checked_body,
    le_f64,
};
use super::spec::ParamSpec;

/// The version of positional records.
pub(super) const VERSION: u16 = 2;

/// The ids of a version-2 record's values, by position: the parameter
/// table of that firmware. Builds without galvo output wrote the first
/// [`GIMBAL_VALUES`], builds with it all of them.
const V2_ORDER: [u16; 54] = [
    10, 11, 20, 21, 22, 23, 24, 25, // geometry, grid, board
    30, 31, 32, 33, // motion
    40, 41, 42, 43, 44, 45, // yaw
    50, 51, 52, 53, 54, 55, // pitch
    60, // laser
    70, 71, 72, 73, 74, 75, // error model x
    80, 81, 82, 83, 84, 85, // error model y
    100, 101, 110, 111, 112, 113, // galvo geometry, DAC
    120, 121, 122, 123, 124, 125, // galvo drive, sample period
    130, 140, 141, 150, 151, // planner, laser delays, marking
];

/// Values in a version-2 record of a build without galvo output.
const GIMBAL_VALUES: usize = 37;

/// Bytes of a positional record of `values` values.
pub(super) const fn len(values: usize) -> usize {
    HEADER_LEN + VALUE_LEN * values + CRC_LEN
}

/// Bytes of the longest version-2 record.
pub(super) const MAX_LEN: usize = len(V2_ORDER.len());

/// Parses a version-2 record of `count` values against `table`.
pub(super) fn decode(
    table: &[ParamSpec],
    bytes: &[u8],
    count: usize,
) -> Result<LoadedRecord, RecordError> {
    // The only two layouts version 2 had.
    if count != GIMBAL_VALUES && count != V2_ORDER.len() {
        return Err(RecordError::WrongVersion(VERSION));
    }
    let body = checked_body(bytes, len(count))?;
    let values = body
        .get(HEADER_LEN..)
        .unwrap_or(&[])
        .chunks_exact(VALUE_LEN);
    let mut loading = Loading::new(table);
    for (&id, value) in V2_ORDER.iter().zip(values) {
        loading.entry(id, le_f64(value).ok_or(RecordError::Corrupt)?)?;
    }
    loading.finish(RecordLayout::Positional)
}
