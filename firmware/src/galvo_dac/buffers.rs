//! The two DMA rings in main SRAM (`.bss`; the DMA cannot reach the CCM,
//! [`in_main_sram`] is checked at boot): DHR12RD words for DMA1 stream 5,
//! GPIOB BSRR words for DMA2 stream 1.

use core::cell::UnsafeCell;

use galvo_dma::ring::Ring;

/// Samples per half buffer (1.28 ms at the default 10 µs period).
pub const HALF_LEN: usize = 128;
/// The ring of two halves both DMA streams run through.
pub(super) const RING: Ring = Ring::new(HALF_LEN);
/// Words in each ring.
pub(super) const RING_LEN: usize = 2 * HALF_LEN;

/// Main SRAM (SRAM1 + SRAM2), the DMA-reachable RAM.
const SRAM: core::ops::Range<u32> = 0x2000_0000..0x2002_0000;

/// A DMA buffer of the ring. Only whole-word volatile stores and loads go
/// through it: by the refill, by the gate's hook (any context) and, from
/// the other side, by a DMA stream.
#[repr(align(4))]
pub(super) struct DmaWords(UnsafeCell<[u32; RING_LEN]>);

// SAFETY: every access is a single aligned volatile word access (atomic
// on the Cortex-M4); no reference into the array is ever created.
unsafe impl Sync for DmaWords {}

impl DmaWords {
    const fn new() -> Self {
        Self(UnsafeCell::new([0; RING_LEN]))
    }

    pub(super) fn address(&self) -> u32 {
        self.0.get() as u32
    }

    pub(super) fn store(&self, index: usize, word: u32) {
        if index < RING_LEN {
            // SAFETY: in bounds, aligned, one volatile word store.
            unsafe { self.0.get().cast::<u32>().add(index).write_volatile(word) }
        }
    }

    pub(super) fn load(&self, index: usize) -> u32 {
        if index < RING_LEN {
            // SAFETY: in bounds, aligned, one volatile word load.
            unsafe { self.0.get().cast::<u32>().add(index).read_volatile() }
        } else {
            0
        }
    }
}

/// DHR12RD words, read by DMA1 stream 5.
pub(super) static DAC_WORDS: DmaWords = DmaWords::new();
/// GPIOB BSRR words, read by DMA2 stream 1.
pub(super) static LASER_WORDS: DmaWords = DmaWords::new();

/// Zeroes every laser word: from the next update on the laser stream
/// writes nothing. The gate's close hook calls it, then pulls PB0 low.
pub fn darken_laser_stream() {
    for i in 0..RING_LEN {
        LASER_WORDS.store(i, 0);
    }
    cortex_m::asm::dsb();
}

/// Whether both rings lie in main SRAM.
pub(super) fn in_main_sram() -> bool {
    SRAM.contains(&DAC_WORDS.address()) && SRAM.contains(&LASER_WORDS.address())
}
