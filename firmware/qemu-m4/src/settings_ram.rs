//! The saved settings in a RAM region that outlives a reset of the board
//! (the top 64 KiB of the MPS2's data RAM, outside the image: see
//! `memory.x`), seen as a NOR flash so laser-app's own store
//! (`FlashSettingsStore`, sequential-storage) keeps the record exactly as it
//! does in the STM32's flash sectors. Programming behaves as NOR: it can
//! only clear bits, erasing sets a whole sector to 0xFF.
//!
//! QEMU starts the board with zeroed RAM; the first boot formats the
//! region (erased sectors and a magic word in a header before them), later
//! boots find the magic word and keep what is there.

use embedded_storage_async::nor_flash::{
    ErrorType, MultiwriteNorFlash, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use laser_app::settings::store::FlashSettingsStore;
use sequential_storage::map::MapConfig;

unsafe extern "C" {
    /// Start of the settings region (`memory.x`).
    static _settings_ram_start: u8;
}

/// Bytes per erase unit.
pub const SECTOR_BYTES: usize = 8 * 1024;
/// Sectors the store uses.
pub const SECTORS: usize = 2;
/// Header before the sectors (the magic word, padded).
const HEADER_BYTES: usize = 32;
/// Marks a formatted region ("LSR1").
const MAGIC: u32 = 0x3152_534C;
/// Bytes programmed at a time.
const WORD_BYTES: usize = 4;

/// Bad argument to the RAM flash (out of range or misaligned).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RamFlashError(NorFlashErrorKind);

impl NorFlashError for RamFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        self.0
    }
}

/// The settings region as a NOR flash of [`SECTORS`] × [`SECTOR_BYTES`].
pub struct RamFlash {
    base: *mut u8,
}

// SAFETY: the region is only ever reached through the one `RamFlash`
// (made once, in `settings_store`), owned by the sequencer task.
unsafe impl Send for RamFlash {}

impl RamFlash {
    const CAPACITY: usize = SECTORS * SECTOR_BYTES;

    /// The region, formatted (all sectors erased) unless a previous boot
    /// left its magic word.
    fn take() -> Self {
        // The region is 64 KiB of RAM no section of the image uses
        // (`memory.x`); header + sectors fit in it.
        let header = (&raw const _settings_ram_start).cast_mut();
        let magic = header.cast::<u32>();
        // SAFETY: as above; the header is word-aligned (the region starts
        // on a 64 KiB boundary).
        let base = unsafe { header.add(HEADER_BYTES) };
        let flash = Self { base };
        // SAFETY: as above.
        if unsafe { magic.read_volatile() } != MAGIC {
            flash.fill(0, Self::CAPACITY, 0xFF);
            // SAFETY: as above.
            unsafe { magic.write_volatile(MAGIC) };
        }
        flash
    }

    fn check(offset: u32, len: usize, align: usize) -> Result<usize, RamFlashError> {
        let start = offset as usize;
        if !start.is_multiple_of(align) || !len.is_multiple_of(align) {
            return Err(RamFlashError(NorFlashErrorKind::NotAligned));
        }
        match start.checked_add(len) {
            Some(end) if end <= Self::CAPACITY => Ok(start),
            _ => Err(RamFlashError(NorFlashErrorKind::OutOfBounds)),
        }
    }

    fn fill(&self, start: usize, len: usize, value: u8) {
        for i in start..start + len {
            // SAFETY: `i` is below CAPACITY (checked by the callers).
            unsafe { self.base.add(i).write_volatile(value) };
        }
    }
}

impl ErrorType for RamFlash {
    type Error = RamFlashError;
}

impl ReadNorFlash for RamFlash {
    const READ_SIZE: usize = 1;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), RamFlashError> {
        let start = Self::check(offset, bytes.len(), Self::READ_SIZE)?;
        for (i, b) in bytes.iter_mut().enumerate() {
            // SAFETY: within the capacity (checked).
            *b = unsafe { self.base.add(start + i).read_volatile() };
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        Self::CAPACITY
    }
}

impl NorFlash for RamFlash {
    const WRITE_SIZE: usize = WORD_BYTES;
    const ERASE_SIZE: usize = SECTOR_BYTES;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), RamFlashError> {
        let len = (to as usize)
            .checked_sub(from as usize)
            .ok_or(RamFlashError(NorFlashErrorKind::OutOfBounds))?;
        let start = Self::check(from, len, SECTOR_BYTES)?;
        self.fill(start, len, 0xFF);
        Ok(())
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), RamFlashError> {
        let start = Self::check(offset, bytes.len(), WORD_BYTES)?;
        for (i, &b) in bytes.iter().enumerate() {
            // SAFETY: within the capacity (checked). NOR programming
            // only clears bits.
            unsafe {
                let cell = self.base.add(start + i);
                cell.write_volatile(cell.read_volatile() & b);
            }
        }
        Ok(())
    }
}

/// Programming a word again clears more bits, as on the STM32F4.
impl MultiwriteNorFlash for RamFlash {}

/// The settings store the sequencer uses: laser-app's store over the RAM
/// region.
pub type RamSettings = FlashSettingsStore<RamFlash>;

/// The store over the settings region (formatted on the first boot).
pub fn settings_store() -> RamSettings {
    FlashSettingsStore::new(
        RamFlash::take(),
        const { MapConfig::new(0..(SECTORS * SECTOR_BYTES) as u32) },
    )
}
