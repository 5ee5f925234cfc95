//! Where the settings record is kept: a power-fail-safe key/value map
//! (`sequential-storage`) over two flash sectors, one piece of code for the
//! target and the simulator. The board supplies only the flash (anything
//! implementing `embedded-storage-async`'s NOR-flash traits) and the range.
//!
//! A `save` appends the new record after the old one (CRC-checked items);
//! only when a sector is full does the map erase the other sector and move
//! the newest record there first. A power cut at any point leaves either
//! the old record or the new one readable, never neither.
//!
//! Earlier firmware wrote the record raw at the start of the range's last
//! sector (sector 11 on the target). Such a record is loaded as it is until
//! the first `save`, which migrates it without a window of loss and without
//! the map ever reading the raw record as one of its pages (`migrate.rs`):
//! the new record goes into the first sector, which is closed, and only
//! then is the last sector erased; a cut in that erase is repaired by the
//! map as a cut hand-over.
//!
//! Presets are items of the same map, one per preset (`presets.rs`): a
//! preset is written or cleared at once ([`SettingsStore::save_preset`]),
//! with the same guarantee (a cut leaves the old or the new preset), and
//! read when it is called ([`SettingsStore::load_preset`]). When a sector
//! fills, the map moves the live presets with the newest record. While a
//! record of the earlier layout is there, presets are refused until the
//! first `save` has migrated it.

use core::ops::Range;

use embedded_storage_async::nor_flash::{MultiwriteNorFlash, NorFlash};
use sequential_storage::cache::{Cache, Uncached};
use sequential_storage::map::{MapConfig, MapStorage};

use super::migrate::write_closed_first_page;
use super::presets::{
    PRESET_VALUE_LEN, StoreKey, decode_preset, encode_preset, is_preset, savable,
};
use super::record::{MAX_RECORD_LEN, intact_record_len};
use crate::domain::PointCm;
use crate::log;

/// Where settings are saved: [`FlashSettingsStore`] over the target's flash
/// sectors 10 and 11, or over the simulator's model of them.
#[allow(async_fn_in_trait)]
pub trait SettingsStore {
    /// Reads the saved record into `buf`; returns the bytes read (0 when
    /// nothing is saved).
    async fn load(&mut self, buf: &mut [u8]) -> usize;
    /// Replaces the saved record; `Err` carries a message for the user.
    async fn save(&mut self, record: &[u8]) -> Result<(), &'static str>;
    /// The board point of preset `n` (1–255), cm, when one is saved.
    async fn load_preset(&mut self, n: u8) -> Option<PointCm>;
    /// Saves board point `point` (cm) as preset `n` (1–255), or clears
    /// preset `n` (`None`), at once; `Err` carries a message for the user.
    async fn save_preset(&mut self, n: u8, point: Option<PointCm>) -> Result<(), &'static str>;
}

/// Map key of the settings record.
const RECORD_KEY: StoreKey = StoreKey::Record;

/// Scratch buffer for one map item (key byte + the longest record this
/// build loads, of either layout), padded to the largest flash word
/// `sequential-storage` supports (32 bytes).
const ITEM_BUFFER_LEN: usize = (1 + MAX_RECORD_LEN).next_multiple_of(32);

/// Bytes read at a time when checking that a sector is erased.
const ERASED_CHECK_CHUNK: usize = 64;

type NoCache = Cache<Uncached, Uncached, Uncached, StoreKey>;

/// The settings store: a [`MapStorage`] over the flash range given by the
/// board, plus the migration of a record in the earlier raw layout.
pub struct FlashSettingsStore<F: NorFlash> {
    map: MapStorage<StoreKey, F, NoCache>,
}

impl<F: MultiwriteNorFlash> FlashSettingsStore<F> {
    /// A store in `config`'s range (whole erase units of `F`, at least two;
    /// build it in a `const` block so a bad range fails to compile):
    /// sectors 10 and 11 on the STM32F407.
    pub fn new(flash: F, config: MapConfig<F>) -> Self {
        Self {
            map: MapStorage::new(flash, config, Cache::new_uncached()),
        }
    }

    /// The flash range, bytes from the start of the flash.
    pub fn range(&self) -> Range<u32> {
        self.map.flash_range()
    }

    /// Gives the flash back.
    pub fn into_flash(self) -> F {
        self.map.destroy().0
    }

    /// Offset of a record in the earlier layout: the start of the last
    /// sector of the range.
    fn legacy_offset(&self) -> u32 {
        self.range().end - F::ERASE_SIZE as u32
    }

    /// The length of a complete record in the earlier layout, read into
    /// `buf`, if there is one.
    async fn read_legacy(&mut self, buf: &mut [u8; ITEM_BUFFER_LEN]) -> Option<usize> {
        let at = self.legacy_offset();
        // A record in the earlier layout lies within the last sector.
        let buf = buf.get_mut(..F::ERASE_SIZE.min(ITEM_BUFFER_LEN))?;
        self.map.flash().read(at, buf).await.ok()?;
        intact_record_len(buf)
    }

    /// Whether `sector` (offset of an erase unit) reads fully erased.
    async fn is_erased(&mut self, sector: u32) -> Result<bool, F::Error> {
        let mut chunk = [0u8; ERASED_CHECK_CHUNK];
        let end = sector + F::ERASE_SIZE as u32;
        let mut at = sector;
        while at < end {
            let n = ERASED_CHECK_CHUNK.min((end - at) as usize);
            let part = chunk.get_mut(..n).unwrap_or(&mut []);
            self.map.flash().read(at, part).await?;
            if part.iter().any(|b| *b != 0xFF) {
                return Ok(false);
            }
            at += n as u32;
        }
        Ok(true)
    }

    /// The first `save` after an update from the earlier layout: the map's
    /// other sectors are emptied before it writes anything (they may hold
    /// anything; the old record still loads meanwhile).
    async fn prepare_migration(&mut self) -> Result<(), &'static str> {
        let legacy = self.legacy_offset();
        let mut sector = self.range().start;
        while sector < legacy {
            if !self.is_erased(sector).await.map_err(|_| READ_FAILED)? {
                let end = sector + F::ERASE_SIZE as u32;
                self.map
                    .flash()
                    .erase(sector, end)
                    .await
                    .map_err(|_| "flash erase failed")?;
            }
            sector += F::ERASE_SIZE as u32;
        }
        Ok(())
    }

    /// The first `save` after an update from the earlier layout: the new
    /// record in the closed first sector (the old one loads meanwhile),
    /// then the old record's sector erased (see `migrate.rs`).
    async fn migrate(
        &mut self,
        item: &mut [u8; ITEM_BUFFER_LEN],
        record: &[u8],
    ) -> Result<(), &'static str> {
        self.prepare_migration().await?;
        let range = self.range();
        write_closed_first_page(self.map.flash(), range, item, record).await?;
        let legacy = self.legacy_offset();
        self.map
            .flash()
            .erase(legacy, legacy + F::ERASE_SIZE as u32)
            .await
            .map_err(|_| "flash erase failed")
    }
}

const READ_FAILED: &str = "flash read failed";
const WRITE_FAILED: &str = "flash write failed";

/// A short description of a store error, for the user and the log.
fn describe<E>(e: &sequential_storage::Error<E>) -> &'static str {
    match e {
        sequential_storage::Error::Storage { .. } => WRITE_FAILED,
        sequential_storage::Error::Corrupted { .. } => "settings flash corrupt",
        _ => "settings flash error",
    }
}

impl<F: MultiwriteNorFlash> SettingsStore for FlashSettingsStore<F> {
    async fn load(&mut self, buf: &mut [u8]) -> usize {
        let mut item = [0u8; ITEM_BUFFER_LEN];
        let record: &[u8] = if let Some(len) = self.read_legacy(&mut item).await {
            log::info!("settings: record in the earlier layout; migrated at the next save");
            item.get(..len).unwrap_or(&[])
        } else {
            match self.map.fetch_item::<&[u8]>(&mut item, &RECORD_KEY).await {
                Ok(Some(record)) => record,
                Ok(None) => &[],
                Err(e) => {
                    log::warning!("settings: flash unreadable ({})", describe(&e));
                    &[]
                }
            }
        };
        let n = record.len().min(buf.len());
        if let (Some(dst), Some(src)) = (buf.get_mut(..n), record.get(..n)) {
            dst.copy_from_slice(src);
        }
        n
    }

    async fn save(&mut self, record: &[u8]) -> Result<(), &'static str> {
        let mut item = [0u8; ITEM_BUFFER_LEN];
        if self.read_legacy(&mut item).await.is_some() {
            self.migrate(&mut item, record).await?;
            log::info!("settings migrated and saved ({} bytes)", record.len());
            return Ok(());
        }
        match self.map.store_item(&mut item, &RECORD_KEY, &record).await {
            Ok(()) => {}
            Err(sequential_storage::Error::Corrupted { .. }) => {
                // The map could not repair itself. Start afresh only when
                // no saved record loads any more (nothing left to lose).
                if let Ok(Some(_)) = self.map.fetch_item::<&[u8]>(&mut item, &RECORD_KEY).await {
                    return Err("settings flash corrupt");
                }
                log::warning!("settings: flash corrupt beyond repair; erasing it");
                self.map.erase_all().await.map_err(|e| describe(&e))?;
                self.map
                    .store_item(&mut item, &RECORD_KEY, &record)
                    .await
                    .map_err(|e| describe(&e))?;
            }
            Err(e) => return Err(describe(&e)),
        }
        log::info!("settings saved ({} bytes)", record.len());
        Ok(())
    }

    async fn load_preset(&mut self, n: u8) -> Option<PointCm> {
        if !is_preset(n) {
            return None;
        }
        let mut item = [0u8; ITEM_BUFFER_LEN];
        if self.read_legacy(&mut item).await.is_some() {
            // The earlier layout had no presets.
            return None;
        }
        let key = StoreKey::Preset(n);
        match self.map.fetch_item::<&[u8]>(&mut item, &key).await {
            Ok(value) => value.and_then(decode_preset),
            Err(e) => {
                log::warning!("preset {}: flash unreadable ({})", n, describe(&e));
                None
            }
        }
    }

    async fn save_preset(&mut self, n: u8, point: Option<PointCm>) -> Result<(), &'static str> {
        if !is_preset(n) {
            return Err("no such preset (1-255)");
        }
        if point.is_some_and(|p| !savable(p)) {
            return Err("preset point beyond the board limit");
        }
        let mut item = [0u8; ITEM_BUFFER_LEN];
        if self.read_legacy(&mut item).await.is_some() {
            // The map does not own the range yet: the first `save`
            // migrates the record, presets come after it.
            return Err("settings in an earlier firmware's layout: save them first");
        }
        let value = point.map(encode_preset);
        let bytes: &[u8] = value.as_ref().map_or(&[], |v| &v[..]);
        debug_assert!(bytes.len() <= PRESET_VALUE_LEN);
        self.map
            .store_item(&mut item, &StoreKey::Preset(n), &bytes)
            .await
            .map_err(|e| describe(&e))?;
        log::info!(
            "preset {} {}",
            n,
            if point.is_some() { "saved" } else { "cleared" }
        );
        Ok(())
    }
}
