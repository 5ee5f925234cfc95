//! Settings flash as the firmware before parameter ids left it (fixture:
//! the settings sectors after it saved a version-2 positional record with
//! the galvo parameters; only the written start of the image is stored, the
//! rest of both sectors is erased): the store reads that record, a boot
//! loads exactly its values, and the next `save` writes the id-keyed record
//! of the same settings.

use laser_app::settings::{RecordLayout, Settings};
use laser_sim::world::{
    SETTINGS_SECTOR_BYTES, SETTINGS_SECTORS, SimOptions, SimReport, load_settings_record,
};
use system_tests::{run_with, terminal_lines};

/// The written start of the settings sectors.
const V2_FLASH: &[u8] =
    include_bytes!("../../firmware/app/src/settings/tests/fixtures/settings_flash_v2_galvo.bin");
/// The record it holds (its values are checked in laser-app's
/// `settings::tests::record`).
const V2_RECORD: &[u8] =
    include_bytes!("../../firmware/app/src/settings/tests/fixtures/record_v2_galvo.bin");

/// Both settings sectors as the earlier firmware left them.
fn v2_image() -> Vec<u8> {
    let mut image = V2_FLASH.to_vec();
    image.resize(SETTINGS_SECTORS * SETTINGS_SECTOR_BYTES, 0xFF);
    image
}

/// The `get <param>` line for `param`.
fn get_line<'a>(report: &'a SimReport, param: &str) -> &'a str {
    let prefix = format!("{param} = ");
    terminal_lines(report)
        .into_iter()
        .find(|l| l.starts_with(&prefix))
        .unwrap_or_else(|| panic!("no `{param}` line: {:?}", terminal_lines(report)))
}

#[test]
fn the_store_reads_the_record_the_earlier_firmware_saved() {
    let record = load_settings_record(v2_image()).expect("a saved record");
    assert_eq!(record, V2_RECORD);
    let loaded = Settings::load_record(&record).expect("it loads");
    assert_eq!(loaded.layout, RecordLayout::Positional);
    // The stepper's 24 parameters, `$11` and the PELCO port's 3 came
    // later: at their defaults.
    assert_eq!((loaded.unknown, loaded.defaulted), (0, 28));
}

#[test]
fn a_boot_from_the_earlier_flash_has_its_values_and_save_migrates_them() {
    let report = run_with(
        "get dwell_ms\nget yaw.dir\nget galvo.d_mm\nget galvo.planner\nsave\n",
        SimOptions {
            settings_flash: Some(v2_image()),
            ..SimOptions::default()
        },
    );
    assert!(get_line(&report, "dwell_ms").starts_with("dwell_ms = 250  #"));
    assert!(get_line(&report, "yaw.dir").starts_with("yaw.dir = -1  #"));
    assert!(get_line(&report, "galvo.d_mm").starts_with("galvo.d_mm = 350  #"));
    assert!(get_line(&report, "galvo.planner").starts_with("galvo.planner = 1  #"));
    assert_eq!(terminal_lines(&report).last(), Some(&"ok"), "save");
    let saved = load_settings_record(report.settings_flash).expect("a saved record");
    let migrated = Settings::load_record(&saved).expect("it loads");
    assert!(migrated.is_exact(), "{migrated:?}");
    assert_eq!(Ok(migrated.settings), Settings::from_record(V2_RECORD));
}
