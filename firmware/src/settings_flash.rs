//! Settings record in the last flash sector (sector 11, 128 KiB at
//! 0x080E_0000 on the STM32F407VG), far from the firmware image.
//!
//! `save` erases the sector and writes the record (versioned and CRC-checked
//! by `laser_app::settings`); the CPU stalls for the erase (~1–2 s), which
//! the watchdog timeout allows for.

use embassy_stm32::flash::{Blocking, Flash};
use laser_app::sequencer::SettingsStore;

/// Offset of the settings sector from the start of flash, bytes.
const SECTOR_OFFSET: u32 = 0x000E_0000;
/// Size of the settings sector, bytes.
const SECTOR_BYTES: u32 = 128 * 1024;

/// The settings sector.
pub struct FlashSettings {
    flash: Flash<'static, Blocking>,
}

impl FlashSettings {
    /// Wraps the flash peripheral.
    pub fn new(flash: Flash<'static, Blocking>) -> Self {
        Self { flash }
    }
}

impl SettingsStore for FlashSettings {
    async fn load(&mut self, buf: &mut [u8]) -> usize {
        match self.flash.blocking_read(SECTOR_OFFSET, buf) {
            Ok(()) => buf.len(),
            Err(e) => {
                defmt::warn!("settings: flash read failed: {}", defmt::Debug2Format(&e));
                0
            }
        }
    }

    async fn save(&mut self, record: &[u8]) -> Result<(), &'static str> {
        self.flash
            .blocking_erase(SECTOR_OFFSET, SECTOR_OFFSET + SECTOR_BYTES)
            .map_err(|_| "flash erase failed")?;
        // Flash writes go in whole 32-bit words here: pad the record.
        let mut padded = [0xFFu8; laser_app::settings::RECORD_LEN.next_multiple_of(4)];
        if let Some(head) = padded.get_mut(..record.len()) {
            head.copy_from_slice(record);
        }
        self.flash
            .blocking_write(SECTOR_OFFSET, &padded)
            .map_err(|_| "flash write failed")?;
        defmt::info!("settings saved ({} bytes)", record.len());
        Ok(())
    }
}
