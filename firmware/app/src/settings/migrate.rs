//! Migration of a record in the earlier raw layout (written at the start of
//! the range's last sector) into the settings map, without a window of loss
//! and without the map ever reading the raw record as one of its pages.
//!
//! The raw record's first byte has zero bits, so the map would take the
//! last sector for a page it writes in and parse the raw record as items.
//! Instead, while the raw record stays intact (and is what a boot loads):
//! 1. the other sectors are erased;
//! 2. the new record is written by a map that sees the last sector erased
//!    ([`HideSector`]), so it lands in the first sector;
//! 3. the first sector is closed (the map's end marker);
//! 4. the last sector is erased.
//!
//! Until step 4 starts the raw record loads; a cut during it leaves the
//! last sector erased or torn, which the map reads as it reads a cut
//! hand-over from the first sector (closed, holding the new record) to the
//! last: its own repair erases the last sector again and moves the record.

use core::ops::Range;

use embedded_storage_async::nor_flash::{ErrorType, NorFlash, ReadNorFlash};
use sequential_storage::cache::{Cache, Uncached};
use sequential_storage::map::{MapConfig, MapStorage};

use super::presets::StoreKey;

/// A flash that reads the sector at `hidden` as erased and takes no
/// writes or erases there (it only notes that one was asked for).
pub(super) struct HideSector<'a, F> {
    /// The real flash.
    pub flash: &'a mut F,
    /// Offset of the hidden sector (one erase unit).
    pub hidden: u32,
    /// Whether a write or erase into the hidden sector was asked for.
    pub touched: bool,
}

impl<F: NorFlash> HideSector<'_, F> {
    fn hidden_range(&self) -> Range<u32> {
        self.hidden..self.hidden + F::ERASE_SIZE as u32
    }

    fn overlaps(&self, from: u32, to: u32) -> bool {
        let h = self.hidden_range();
        from < h.end && h.start < to
    }
}

impl<F: ErrorType> ErrorType for HideSector<'_, F> {
    type Error = F::Error;
}

impl<F: NorFlash> ReadNorFlash for HideSector<'_, F> {
    const READ_SIZE: usize = F::READ_SIZE;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.flash.read(offset, bytes).await?;
        let h = self.hidden_range();
        for (at, b) in (offset..).zip(bytes.iter_mut()) {
            if h.contains(&at) {
                *b = 0xFF;
            }
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.flash.capacity()
    }
}

impl<F: NorFlash> NorFlash for HideSector<'_, F> {
    const WRITE_SIZE: usize = F::WRITE_SIZE;
    const ERASE_SIZE: usize = F::ERASE_SIZE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        if self.overlaps(from, to) {
            self.touched = true;
            return Ok(());
        }
        self.flash.erase(from, to).await
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        if self.overlaps(offset, offset + bytes.len() as u32) {
            self.touched = true;
            return Ok(());
        }
        self.flash.write(offset, bytes).await
    }
}

/// Steps 2 and 3: writes `record` as the map's record item into the first
/// sector of `range` (the others erased, the last one `hidden`) and closes
/// that sector. `item` is scratch space for one item.
pub(super) async fn write_closed_first_page<F: NorFlash>(
    flash: &mut F,
    range: Range<u32>,
    item: &mut [u8],
    record: &[u8],
) -> Result<(), &'static str> {
    const FAILED: &str = "settings migration failed";
    let hidden = range.end - F::ERASE_SIZE as u32;
    let first_end = range.start + F::ERASE_SIZE as u32;
    let config = MapConfig::try_new(range).map_err(|_| FAILED)?;
    let view = HideSector {
        flash,
        hidden,
        touched: false,
    };
    let mut map: MapStorage<StoreKey, _, Cache<Uncached, Uncached, Uncached, StoreKey>> =
        MapStorage::new(view, config, Cache::new_uncached());
    map.store_item(item, &StoreKey::Record, &record)
        .await
        .map_err(|_| "flash write failed")?;
    let view = map.destroy().0;
    if view.touched {
        return Err(FAILED);
    }
    // The map's end marker: a word of zeros at the end of the page, as
    // `sequential-storage` closes a page it has filled.
    let zero = [0u8; 32];
    let word = zero.get(..F::WRITE_SIZE.max(F::READ_SIZE)).ok_or(FAILED)?;
    view.flash
        .write(first_end - word.len() as u32, word)
        .await
        .map_err(|_| "flash write failed")
}
