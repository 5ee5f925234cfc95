//! What the two DMA streams write: one DHR12RD word per sample (both axes
//! on the same trigger) and one GPIOB BSRR word per sample (the laser).
//!
//! Alignment: on each TIM8 update the DAC first outputs the word the DMA
//! loaded at the previous update, then requests the next one (RM0090
//! §14.3.8), so DAC word `k` of the ring is *output* at update `k + 1`;
//! the laser stream's BSRR write acts at once, at update `k`. The laser
//! word of sample `k` therefore goes one slot later, `k + 1`: each half's
//! first laser slot carries the previous half's last sample
//! ([`LaserTrack::pack`]), so a refill only ever touches its own half.

/// Largest 12-bit DAC code.
pub const DAC_CODE_MAX: u16 = 4095;

/// Updates between the DMA reading a DAC word and the DAC outputting it.
pub const DAC_OUTPUT_DELAY: usize = 1;

/// The DHR12RD word of one sample: channel 1 (X, PA4) in bits 0–11,
/// channel 2 (Y, PA5) in bits 16–27 (RM0090 §14.5.9). Codes above
/// [`DAC_CODE_MAX`] saturate.
pub const fn dhr12rd(x_code: u16, y_code: u16) -> u32 {
    let x = if x_code > DAC_CODE_MAX {
        DAC_CODE_MAX
    } else {
        x_code
    };
    let y = if y_code > DAC_CODE_MAX {
        DAC_CODE_MAX
    } else {
        y_code
    };
    (y as u32) << 16 | x as u32
}

/// The BSRR word that drives `pin` (0–15) high.
pub const fn bsrr_set(pin: u8) -> u32 {
    1 << (pin & 15)
}

/// The BSRR word that drives `pin` (0–15) low.
pub const fn bsrr_reset(pin: u8) -> u32 {
    1 << ((pin & 15) + 16)
}

/// The laser word of a sample: set while lit; reset on the first dark
/// sample after a lit one; otherwise 0, which writes nothing, so a dark
/// galvo stream leaves the pin as the gimbal's laser switch set it.
pub const fn laser_word(pin: u8, lit: bool, previous_lit: bool) -> u32 {
    match (lit, previous_lit) {
        (true, _) => bsrr_set(pin),
        (false, true) => bsrr_reset(pin),
        (false, false) => 0,
    }
}

/// The laser stream's state across halves: the pin, the last packed
/// sample's laser state, the word that goes into the next half's first
/// slot, and the laser-gate generation they were computed under.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LaserTrack {
    pin: u8,
    lit: bool,
    carry: u32,
    generation: u32,
}

impl LaserTrack {
    /// Dark, for `pin` (0–15) of the GPIO port the laser stream writes.
    pub const fn new(pin: u8) -> Self {
        Self {
            pin,
            lit: false,
            carry: 0,
            generation: 0,
        }
    }

    /// Forgets the laser state: the gate darkened the stream (the words
    /// were zeroed, the pin pulled low), nothing computed before may light.
    pub fn darken(&mut self) {
        self.lit = false;
        self.carry = 0;
    }

    /// Packs one half: `dac[i]` is sample `i`'s DHR12RD word;
    /// `laser[0]` the previous half's last laser word and `laser[i]`
    /// sample `i - 1`'s; the last sample's word is kept for the next half.
    /// `samples` are (x code, y code, lit); lit samples shine only when
    /// `gate_passes` (the gate is open at `generation`), and a half of a
    /// new generation does not inherit the previous half's laser. Fills
    /// `min(dac.len(), laser.len())` slots; missing samples repeat the
    /// last one (dark, at code 0 when there is none).
    pub fn pack(
        &mut self,
        generation: u32,
        gate_passes: bool,
        samples: impl IntoIterator<Item = (u16, u16, bool)>,
        dac: &mut [u32],
        laser: &mut [u32],
    ) {
        if generation != self.generation || !gate_passes {
            self.darken();
        }
        self.generation = generation;
        let n = dac.len().min(laser.len());
        let mut samples = samples.into_iter();
        let mut last = (0, 0, false);
        for i in 0..n {
            let (x, y, lit) = samples.next().unwrap_or((last.0, last.1, false));
            last = (x, y, lit);
            let lit = lit && gate_passes;
            dac[i] = dhr12rd(x, y);
            laser[i] = self.carry;
            self.carry = laser_word(self.pin, lit, self.lit);
            self.lit = lit;
        }
    }
}

/// Whether a packed half replays exactly as written when the DMA plays it
/// again: every DAC word and every laser word the same. The first half of
/// a hold whose laser state differs from the samples before it does not
/// (its first slots carry that change: the previous sample's word, and a
/// reset after a lit one); the next half of the same hold does.
pub fn replays_identically(dac: &[u32], laser: &[u32]) -> bool {
    dac.iter().all(|w| Some(w) == dac.first()) && laser.iter().all(|w| Some(w) == laser.first())
}

#[cfg(test)]
mod tests;
