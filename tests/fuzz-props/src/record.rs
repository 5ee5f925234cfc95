//! The saved settings record (`settings/record.rs`), through its public
//! API only: `Settings::to_record`, `Settings::load_record`,
//! `claimed_record_len`, `RECORD_LEN`, `MAX_RECORD_LEN` and `crc32`.
//!
//! Properties:
//! * `load_record` never panics, whatever the bytes;
//! * a record it accepts is valid settings; an exact one (id-keyed, with
//!   exactly this build's parameters) re-serialises to exactly the same
//!   record bytes (nothing is silently changed on load), any other (a
//!   positional record of the earlier layout, unknown ids skipped, missing
//!   ones defaulted) re-serialises to an exact record of the same settings;
//! * settings built by any sequence of accepted `set`s round-trip through
//!   the record;
//! * an accepted record with any error burst of up to 32 bits, or cut
//!   short, is refused.
//!
//! Random bytes almost never carry a valid CRC-32, so each input is also
//! tried with its checksum fixed up ([`with_valid_checksum`]): that lets
//! the fuzzer reach the value checks behind the CRC.

use laser_app::settings::{
    LoadedRecord, MAX_RECORD_LEN, PARAMS, RECORD_LEN, Settings, claimed_record_len, crc32,
};

use crate::Bytes;

/// What one input exercised.
#[derive(Debug, Default)]
pub struct Summary {
    /// The input as given was accepted.
    pub accepted: bool,
    /// The input as given was accepted as a record of this build's layout
    /// (not migrated, no unknown or defaulted parameter).
    pub exact: bool,
    /// The input with its checksum fixed up was accepted.
    pub accepted_with_checksum: bool,
    /// `set`s accepted while building the generated settings.
    pub generated_sets: usize,
}

/// Runs the record properties on `data`; panics when one fails.
pub fn check(data: &[u8]) -> Summary {
    let mut summary = Summary::default();
    if let Ok(loaded) = Settings::load_record(data) {
        accepted(data, &loaded);
        summary.accepted = true;
        summary.exact = loaded.is_exact();
        corruptions_are_refused(data, data);
    }
    let fixed = with_valid_checksum(data);
    if let Ok(loaded) = Settings::load_record(&fixed) {
        accepted(&fixed, &loaded);
        summary.accepted_with_checksum = true;
        corruptions_are_refused(&fixed, data);
    }
    let (settings, sets) = generated_settings(data);
    summary.generated_sets = sets;
    let record = settings.to_record();
    assert_eq!(
        Settings::from_record(&record),
        Ok(settings),
        "settings built with accepted sets do not round-trip"
    );
    let loaded = Settings::load_record(&record).expect("just checked");
    assert!(loaded.is_exact(), "a record of this build is not exact");
    accepted(&record, &loaded);
    corruptions_are_refused(&record, data);
    summary
}

/// `data` cut or zero-padded to the length its own header claims (when
/// it claims one up to [`MAX_RECORD_LEN`], else [`RECORD_LEN`]) with the
/// CRC-32 of the record body written into its last four bytes,
/// little-endian (the record layout: body, then CRC-32 of the body).
pub fn with_valid_checksum(data: &[u8]) -> Vec<u8> {
    let len = claimed_record_len(data)
        .filter(|&len| len <= MAX_RECORD_LEN)
        .unwrap_or(RECORD_LEN);
    let mut record = data.to_vec();
    record.resize(len, 0);
    let body = len - 4;
    let crc = crc32(&record[..body]);
    record[body..].copy_from_slice(&crc.to_le_bytes());
    record
}

/// Properties of a record `load_record` accepted as `loaded`.
fn accepted(bytes: &[u8], loaded: &LoadedRecord) {
    let settings = loaded.settings;
    assert!(settings.validate().is_ok(), "an accepted record is invalid");
    let again = settings.to_record();
    if loaded.is_exact() {
        assert_eq!(
            again[..],
            bytes[..],
            "an accepted record re-serialises differently"
        );
    } else {
        let reloaded = Settings::load_record(&again).expect("a saved record loads");
        assert!(
            reloaded.is_exact() && reloaded.settings == settings,
            "a migrated record does not save as the same settings"
        );
    }
}

/// Error bursts of up to 32 bits anywhere in an accepted record, and every
/// truncation, are refused. Where and how to corrupt comes from `seed`.
fn corruptions_are_refused(record: &[u8], seed: &[u8]) {
    let mut b = Bytes::new(seed);
    let mut tries = 0;
    loop {
        let at = usize::from(b.u16()) % record.len();
        let mask: [u8; 4] = b.array();
        let mask = if mask == [0; 4] { [1, 0, 0, 0] } else { mask };
        let mut bad = record.to_vec();
        for (byte, m) in bad[at..].iter_mut().zip(mask) {
            *byte ^= m;
        }
        if bad != record {
            assert!(
                Settings::from_record(&bad).is_err(),
                "record with bytes {at}.. xor {mask:02x?} accepted"
            );
        }
        tries += 1;
        if b.is_empty() || tries >= 16 {
            break;
        }
    }
    let cut = usize::from(b.u16()) % record.len();
    for len in [cut, record.len() - 1, 8, 0] {
        assert!(
            Settings::from_record(&record[..len]).is_err(),
            "record cut to {len} bytes accepted"
        );
    }
}

/// Settings after a sequence of `set`s chosen by `data` (parameter, then a
/// value inside its range or arbitrary bits); only accepted ones apply.
fn generated_settings(data: &[u8]) -> (Settings, usize) {
    let mut settings = Settings::default();
    let mut b = Bytes::new(data);
    let mut accepted = 0;
    while !b.is_empty() {
        let param = &PARAMS[usize::from(b.u8()) % PARAMS.len()];
        let kind = b.u8();
        let value = if kind & 1 == 0 {
            let frac = f64::from(b.u16()) / f64::from(u16::MAX);
            let v = param.min + (param.max - param.min) * frac;
            if kind & 2 == 0 { v.round() } else { v }
        } else {
            f64::from_bits(b.u64())
        };
        let before = settings;
        match settings.set(param, value) {
            Ok(()) => accepted += 1,
            Err(_) => assert!(settings == before, "refused set changed settings"),
        }
    }
    (settings, accepted)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_record_is_accepted_and_a_fixed_up_copy_too() {
        let record = Settings::default().to_record();
        let s = check(&record);
        assert!(s.accepted && s.accepted_with_checksum);
        let mut broken = record;
        broken[RECORD_LEN - 1] ^= 0xff;
        let s = check(&broken);
        assert!(!s.accepted && s.accepted_with_checksum);
    }
}
