//! Simulated NOR flash with the STM32F407's programming rules, for the
//! settings store: erased bytes read `0xFF`, a program operation writes one
//! 32-bit word and can only clear bits (1 → 0; programming a written word
//! again ANDs it in, as on the F4, which has no ECC), an erase sets a whole
//! sector back to `0xFF`.
//!
//! It can cut the power at any program/erase step: the first `k`
//! operations complete, operation `k` is left undone or torn (a partly
//! programmed word, a partly erased sector), and every access after it
//! fails, as if the MCU had stopped. Booting again means building a new
//! flash from [`SimFlash::image`].
//!
//! With [`FlashTiming::Virtual`] operations take the F407's typical times
//! in the simulator's virtual clock: a word program yields for 16 µs (the
//! async flash driver waits for the end-of-operation interrupt), a sector
//! erase stalls everything for 1 s (the CPU cannot fetch code from a flash
//! bank that is erasing).

use std::cell::RefCell;
use std::rc::Rc;

use embedded_storage_async::nor_flash::{
    ErrorType, MultiwriteNorFlash, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

/// Word program time, µs (STM32F407 datasheet, x32 parallelism, typical).
pub const WORD_PROGRAM_US: u64 = 16;
/// 128 KiB sector erase time, µs (STM32F407 datasheet, x32, typical; 2 s
/// maximum).
pub const SECTOR_ERASE_US: u64 = 1_000_000;

/// Bytes per program operation (one 32-bit word, PSIZE = x32).
pub const WORD_BYTES: usize = 4;

/// How operation `k` of a power cut is left.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tear {
    /// Not started: only the `k` operations before it happened.
    NotStarted,
    /// Half done: a word with only its low two bytes programmed, a sector
    /// with only its first half erased.
    FirstHalf,
    /// Scattered: a word with every other bit that was to be cleared
    /// cleared, a sector with every other word erased.
    EveryOther,
}

impl Tear {
    /// Every way an operation can be left.
    pub const ALL: [Tear; 3] = [Tear::NotStarted, Tear::FirstHalf, Tear::EveryOther];
}

/// Power cut at program/erase operation number `at_op` (counted from 0
/// since the flash was built).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PowerCut {
    /// Operations that complete before the cut.
    pub at_op: u64,
    /// What the cut leaves of operation `at_op`.
    pub tear: Tear,
}

/// Whether flash operations take (virtual) time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlashTiming {
    /// Instant (plain unit tests, no executor).
    Instant,
    /// Typical F407 times on the simulator's virtual clock (inside
    /// `executor::run` only).
    Virtual,
}

/// Counts of what the flash did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FlashStats {
    /// Sector erases.
    pub erases: u64,
    /// Word programs.
    pub word_writes: u64,
    /// Word programs onto a word that was not erased (multi-write).
    pub rewrites: u64,
    /// Time the operations take on the F407 (typical figures), µs.
    pub busy_us: u64,
}

/// Why an access failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimFlashError {
    /// Outside the flash.
    OutOfBounds,
    /// Offset or length not a multiple of the word or sector.
    NotAligned,
    /// The power was cut.
    PowerLost,
}

impl NorFlashError for SimFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            SimFlashError::OutOfBounds => NorFlashErrorKind::OutOfBounds,
            SimFlashError::NotAligned => NorFlashErrorKind::NotAligned,
            SimFlashError::PowerLost => NorFlashErrorKind::Other,
        }
    }
}

/// A flash region `[base, base + len)` of `SECTOR`-byte sectors (offsets
/// count from the start of the whole flash, as on the target). Clones are
/// handles to the same flash (the simulator keeps one to read the flash
/// after a run).
#[derive(Debug, Clone)]
pub struct SimFlash<const SECTOR: usize> {
    state: Rc<RefCell<FlashState<SECTOR>>>,
}

#[derive(Debug)]
struct FlashState<const SECTOR: usize> {
    base: u32,
    bytes: Vec<u8>,
    ops: u64,
    cut: Option<PowerCut>,
    powered: bool,
    timing: FlashTiming,
    stats: FlashStats,
}

impl<const SECTOR: usize> SimFlash<SECTOR> {
    /// Erased flash of `sectors` sectors starting at offset `base`.
    pub fn erased(base: u32, sectors: usize) -> Self {
        Self::from_image(base, vec![0xFF; sectors * SECTOR])
    }

    /// Flash holding `image` (a whole number of sectors) at offset `base`:
    /// a boot from what an earlier run left.
    pub fn from_image(base: u32, image: Vec<u8>) -> Self {
        assert!(
            image.len().is_multiple_of(SECTOR) && (base as usize).is_multiple_of(SECTOR),
            "flash image must be whole sectors"
        );
        Self {
            state: Rc::new(RefCell::new(FlashState {
                base,
                bytes: image,
                ops: 0,
                cut: None,
                powered: true,
                timing: FlashTiming::Instant,
                stats: FlashStats::default(),
            })),
        }
    }

    /// Cuts the power at `cut` (replaces an earlier setting; operations
    /// count from the flash's construction).
    pub fn with_power_cut(self, cut: Option<PowerCut>) -> Self {
        self.state.borrow_mut().cut = cut;
        self
    }

    /// Operations take virtual time (see [`FlashTiming`]).
    pub fn with_timing(self, timing: FlashTiming) -> Self {
        self.state.borrow_mut().timing = timing;
        self
    }

    /// Offset of the first byte.
    pub fn base(&self) -> u32 {
        self.state.borrow().base
    }

    /// A copy of the flash contents.
    pub fn image(&self) -> Vec<u8> {
        self.state.borrow().bytes.clone()
    }

    /// Program/erase operations started so far.
    pub fn ops(&self) -> u64 {
        self.state.borrow().ops
    }

    /// Whether the power is still on.
    pub fn powered(&self) -> bool {
        self.state.borrow().powered
    }

    /// What the flash did.
    pub fn stats(&self) -> FlashStats {
        self.state.borrow().stats
    }

    fn timing(&self) -> FlashTiming {
        self.state.borrow().timing
    }
}

impl<const SECTOR: usize> FlashState<SECTOR> {
    fn index(&self, offset: u32, len: usize) -> Result<usize, SimFlashError> {
        let start = offset
            .checked_sub(self.base)
            .ok_or(SimFlashError::OutOfBounds)? as usize;
        if start + len > self.bytes.len() {
            return Err(SimFlashError::OutOfBounds);
        }
        Ok(start)
    }

    fn check_power(&self) -> Result<(), SimFlashError> {
        if self.powered {
            Ok(())
        } else {
            Err(SimFlashError::PowerLost)
        }
    }

    /// Starts operation number `self.ops`: `None` when it runs to the end,
    /// else how it is torn (the power goes off with it).
    fn begin_op(&mut self) -> Result<Option<Tear>, SimFlashError> {
        self.check_power()?;
        let op = self.ops;
        self.ops += 1;
        match self.cut {
            Some(cut) if cut.at_op == op => {
                self.powered = false;
                Ok(Some(cut.tear))
            }
            _ => Ok(None),
        }
    }

    fn program_word(&mut self, at: usize, word: [u8; WORD_BYTES]) -> Result<(), SimFlashError> {
        let tear = self.begin_op()?;
        let old: [u8; WORD_BYTES] = self.bytes[at..at + WORD_BYTES]
            .try_into()
            .expect("word slice");
        let target = u32::from_le_bytes(old) & u32::from_le_bytes(word);
        let old_bits = u32::from_le_bytes(old);
        let result = match tear {
            None => target,
            Some(Tear::NotStarted) => old_bits,
            Some(Tear::FirstHalf) => (old_bits & 0xFFFF_0000) | (target & 0x0000_FFFF),
            Some(Tear::EveryOther) => {
                // Bits to clear, every other one of them cleared.
                let mut to_clear = old_bits & !target;
                let mut keep = 0u32;
                let mut skip = false;
                while to_clear != 0 {
                    let bit = to_clear & to_clear.wrapping_neg();
                    if skip {
                        keep |= bit;
                    }
                    skip = !skip;
                    to_clear &= !bit;
                }
                target | keep
            }
        };
        if tear.is_none() {
            if old != [0xFF; WORD_BYTES] {
                self.stats.rewrites += 1;
            }
            self.stats.word_writes += 1;
            self.stats.busy_us += WORD_PROGRAM_US;
        }
        self.bytes[at..at + WORD_BYTES].copy_from_slice(&result.to_le_bytes());
        tear.map_or(Ok(()), |_| Err(SimFlashError::PowerLost))
    }

    fn erase_sector(&mut self, at: usize) -> Result<(), SimFlashError> {
        let tear = self.begin_op()?;
        let sector = &mut self.bytes[at..at + SECTOR];
        match tear {
            None => sector.fill(0xFF),
            Some(Tear::NotStarted) => {}
            Some(Tear::FirstHalf) => sector[..SECTOR / 2].fill(0xFF),
            Some(Tear::EveryOther) => {
                for word in sector.chunks_mut(WORD_BYTES).step_by(2) {
                    word.fill(0xFF);
                }
            }
        }
        if tear.is_some() {
            return Err(SimFlashError::PowerLost);
        }
        self.stats.erases += 1;
        // A 128 KiB sector's time, whatever the (scaled) sector size.
        self.stats.busy_us += SECTOR_ERASE_US;
        Ok(())
    }
}

impl<const SECTOR: usize> ErrorType for SimFlash<SECTOR> {
    type Error = SimFlashError;
}

impl<const SECTOR: usize> ReadNorFlash for SimFlash<SECTOR> {
    const READ_SIZE: usize = 1;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        let state = self.state.borrow();
        state.check_power()?;
        let at = state.index(offset, bytes.len())?;
        bytes.copy_from_slice(&state.bytes[at..at + bytes.len()]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        let state = self.state.borrow();
        state.base as usize + state.bytes.len()
    }
}

impl<const SECTOR: usize> NorFlash for SimFlash<SECTOR> {
    const WRITE_SIZE: usize = WORD_BYTES;
    const ERASE_SIZE: usize = SECTOR;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        let start = {
            let state = self.state.borrow();
            state.check_power()?;
            if to < from {
                return Err(SimFlashError::OutOfBounds);
            }
            state.index(from, (to - from) as usize)?
        };
        if !start.is_multiple_of(SECTOR) || !((to - from) as usize).is_multiple_of(SECTOR) {
            return Err(SimFlashError::NotAligned);
        }
        for sector in (start..start + (to - from) as usize).step_by(SECTOR) {
            self.state.borrow_mut().erase_sector(sector)?;
            if self.timing() == FlashTiming::Virtual {
                // The CPU stalls: nothing else runs meanwhile.
                crate::clock::advance_to(crate::clock::now_us() + SECTOR_ERASE_US);
            }
        }
        Ok(())
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        let start = {
            let state = self.state.borrow();
            state.check_power()?;
            state.index(offset, bytes.len())?
        };
        if !start.is_multiple_of(WORD_BYTES) || !bytes.len().is_multiple_of(WORD_BYTES) {
            return Err(SimFlashError::NotAligned);
        }
        for (i, word) in bytes.chunks_exact(WORD_BYTES).enumerate() {
            let word: [u8; WORD_BYTES] = word.try_into().expect("word chunk");
            self.state
                .borrow_mut()
                .program_word(start + i * WORD_BYTES, word)?;
            if self.timing() == FlashTiming::Virtual {
                embassy_time::Timer::after_micros(WORD_PROGRAM_US).await;
            }
        }
        Ok(())
    }
}

impl<const SECTOR: usize> MultiwriteNorFlash for SimFlash<SECTOR> {}

#[cfg(test)]
mod tests;
