//! The settings flash as the target lays it out (sectors 10 and 11 of the
//! STM32F407) and the settings store over it: shared by the simulated
//! board ([`crate::board`]) and the simulation it is assembled into
//! ([`crate::world`]).

use laser_app::sequencer::SettingsStore;
use laser_app::settings::store::FlashSettingsStore;
use sequential_storage::map::MapConfig;

use crate::flash::SimFlash;

/// Bytes per sector of the settings flash (the STM32F407's sectors 10 and
/// 11 are 128 KiB each).
pub const SETTINGS_SECTOR_BYTES: usize = 128 * 1024;
/// The settings flash as the target has it: sectors 10 and 11.
pub type SettingsFlash = SimFlash<SETTINGS_SECTOR_BYTES>;
/// Offset of the settings sectors from the start of flash (0x080C_0000).
pub const SETTINGS_FLASH_OFFSET: u32 = 0x000C_0000;
/// Sectors the settings use.
pub const SETTINGS_SECTORS: usize = 2;

/// The settings store over `flash`, laid out as on the target.
pub fn settings_store(flash: SettingsFlash) -> FlashSettingsStore<SettingsFlash> {
    FlashSettingsStore::new(
        flash,
        const {
            MapConfig::new(
                SETTINGS_FLASH_OFFSET
                    ..SETTINGS_FLASH_OFFSET + (SETTINGS_SECTORS * SETTINGS_SECTOR_BYTES) as u32,
            )
        },
    )
}

/// The record a boot from `image` (the settings sectors) loads, if any.
pub fn load_settings_record(image: Vec<u8>) -> Option<Vec<u8>> {
    let mut store = settings_store(SettingsFlash::from_image(SETTINGS_FLASH_OFFSET, image));
    let mut record = vec![0u8; laser_app::settings::MAX_RECORD_LEN];
    let n = embassy_futures::block_on(store.load(&mut record));
    record.truncate(n);
    (n > 0).then_some(record)
}
