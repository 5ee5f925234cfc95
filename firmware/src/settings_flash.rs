//! The settings flash: sectors 10 and 11 of the STM32F407VG (2 × 128 KiB at
//! 0x080C_0000 and 0x080E_0000, outside the image: see `memory.x`). The
//! store itself (power-fail safe, shared with the simulator) is
//! `laser_app::settings::store`; this board only supplies the flash.
//!
//! Erasing a sector (only when a sector fills up, about every 260 saves, or
//! on the first save after an update from the earlier layout) stalls the
//! CPU for ~1–2 s, which the watchdog timeout allows for; `save` is refused
//! while a pattern runs.

use embassy_stm32::flash::{Async, Error, Flash};
use embedded_storage_async::nor_flash::{ErrorType, MultiwriteNorFlash, NorFlash, ReadNorFlash};
use laser_app::settings::store::FlashSettingsStore;
use sequential_storage::map::MapConfig;

/// Offset of sector 10 from the start of flash, bytes.
const SETTINGS_START: u32 = 0x000C_0000;
/// End of sector 11 (the end of the 1 MiB flash), bytes from its start.
const SETTINGS_END: u32 = 0x0010_0000;

/// The on-chip flash. Words of the STM32F4's flash can be programmed again
/// (clearing more bits; it has no ECC), which the store uses once to retire
/// a record of the earlier layout: hence [`MultiwriteNorFlash`].
pub struct F4Flash(Flash<'static, Async>);

impl ErrorType for F4Flash {
    type Error = Error;
}

impl ReadNorFlash for F4Flash {
    const READ_SIZE: usize = <Flash<'static, Async> as ReadNorFlash>::READ_SIZE;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Error> {
        ReadNorFlash::read(&mut self.0, offset, bytes).await
    }

    fn capacity(&self) -> usize {
        ReadNorFlash::capacity(&self.0)
    }
}

impl NorFlash for F4Flash {
    const WRITE_SIZE: usize = <Flash<'static, Async> as NorFlash>::WRITE_SIZE;
    const ERASE_SIZE: usize = <Flash<'static, Async> as NorFlash>::ERASE_SIZE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Error> {
        NorFlash::erase(&mut self.0, from, to).await
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Error> {
        NorFlash::write(&mut self.0, offset, bytes).await
    }
}

impl MultiwriteNorFlash for F4Flash {}

/// The settings store the sequencer uses.
pub type FlashSettings = FlashSettingsStore<F4Flash>;

/// The settings store over sectors 10 and 11.
pub fn settings_store(flash: Flash<'static, Async>) -> FlashSettings {
    FlashSettingsStore::new(
        F4Flash(flash),
        const { MapConfig::new(SETTINGS_START..SETTINGS_END) },
    )
}
