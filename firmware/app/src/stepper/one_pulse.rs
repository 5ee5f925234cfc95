//! Hardware-timed STEP pulses: what to write into an STM32 timer in
//! one-pulse mode (RM0090 §17.3.15) so that one step event makes exactly
//! one STEP pulse of the configured width on each stepping axis, the DIR
//! setup time after the event when a DIR pin changed in it.
//!
//! The timer (TIM1 on the reference board: channel 1 = pan STEP, channel 2
//! = tilt STEP) counts up from 0 with OPM set, so it stops by itself at its
//! update. A channel in PWM mode 2 is high while `CNT ≥ CCR`: the pulse
//! rises `CCR` counts after the start and falls at the update, `ARR + 1`
//! counts after it (high for `ARR − CCR + 1` counts). A channel whose axis
//! does not step is forced inactive (OCxM = 100): low whatever the counter
//! does. The channel outputs stay enabled, so both pins are always driven
//! (a disabled advanced-timer output is not driven at all). Stopped, the
//! counter rests at 0 < `CCR`: both pins low.
//!
//! [`OnePulseTiming::new`] does the arithmetic once per [`DriverSignals`]
//! (a prescaler if the counts would not fit 16 bits, every count rounded
//! up); [`OnePulseTiming::event`], on the step path, only selects
//! precomputed values (no division, no float).

use super::config::DriverSignals;

/// Output-compare mode "force inactive" (OCxM = 100).
const OCM_FORCE_INACTIVE: u32 = 0b100;
/// Output-compare mode "PWM mode 2" (OCxM = 111): active while `CNT ≥ CCR`.
const OCM_PWM_MODE_2: u32 = 0b111;
/// Bit offsets of OC1M and OC2M in CCMR1 (RM0090 §17.4.7; CCxS = 00:
/// outputs, OCxPE = 0: compare values take effect at once).
const OCM_SHIFT: [u32; 2] = [4, 12];

/// CCMR1 with both channels forced inactive: the STEP pins low.
pub const CCMR1_IDLE: u32 = OCM_FORCE_INACTIVE << OCM_SHIFT[0] | OCM_FORCE_INACTIVE << OCM_SHIFT[1];

/// Counts of a 16-bit timer period: the longest `ARR + 1`, and the
/// largest prescaler divisor (`PSC + 1`).
const COUNTS_16: u64 = 1 << 16;

/// The timer's pulse timing for one set of [`DriverSignals`]: the
/// prescaler and, for events with and without a DIR change, the compare
/// and reload values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OnePulseTiming {
    timer_hz: u32,
    prescaler: u16,
    /// `[no DIR change, DIR changed]`: (CCR, ARR).
    shapes: [(u16, u16); 2],
}

/// What one step event writes into the timer before starting it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OnePulse {
    /// CCMR1: PWM mode 2 for each stepping axis's channel, forced inactive
    /// for the other.
    pub ccmr1: u32,
    /// CCR1 and CCR2: counts from the start to the rising STEP edge (≥ 1).
    pub compare: u16,
    /// ARR: the last count of the pulse (it falls at the update, one count
    /// later).
    pub reload: u16,
}

impl OnePulse {
    /// Counts from the timer's start to the rising STEP edge.
    pub fn rise_counts(&self) -> u32 {
        u32::from(self.compare)
    }

    /// Counts from the timer's start to the falling STEP edge (the update
    /// that stops the timer).
    pub fn fall_counts(&self) -> u32 {
        u32::from(self.reload) + 1
    }

    /// Whether axis `i` (0 pan, 1 tilt) pulses in this event.
    pub fn pulses(&self, i: usize) -> bool {
        (self.ccmr1 >> OCM_SHIFT[i & 1]) & 0b111 == OCM_PWM_MODE_2
    }
}

impl OnePulseTiming {
    /// The timing for `signals` on a timer clocked at `timer_hz`: the
    /// smallest prescaler at which DIR setup plus pulse fit the 16-bit
    /// counter, each rounded up to whole counts (never shorter than
    /// configured, at most one count longer), at least one count each.
    /// Every [`DriverSignals`] fits for timer clocks up to 500 MHz (every
    /// STM32's); above, counts of seconds are clamped to the counter.
    pub fn new(timer_hz: u32, signals: DriverSignals) -> Self {
        let counts = |ns: u32, divisor: u64| {
            (u64::from(ns) * u64::from(timer_hz))
                .div_ceil(1_000_000_000 * divisor)
                .max(1)
        };
        let (setup_ns, pulse_ns) = (signals.dir_setup_ns, signals.pulse_ns);
        // The smallest divisor is at least the total over one period; the
        // rounding up of each part adds at most two counts.
        let total = (u64::from(setup_ns) + u64::from(pulse_ns)).saturating_mul(u64::from(timer_hz));
        let mut divisor = total.div_ceil(1_000_000_000 * COUNTS_16).max(1);
        while divisor < COUNTS_16
            && counts(setup_ns, divisor) + counts(pulse_ns, divisor) > COUNTS_16
        {
            divisor += 1;
        }
        let divisor = divisor.min(COUNTS_16);
        let pulse = counts(pulse_ns, divisor).min(COUNTS_16 - 1);
        let setup = counts(setup_ns, divisor).min(COUNTS_16 - pulse);
        // Whole: every value is ≤ 65 535 by the clamps above.
        let shape = |compare: u64| (compare as u16, (compare + pulse - 1) as u16);
        Self {
            timer_hz,
            prescaler: (divisor - 1) as u16,
            shapes: [shape(1), shape(setup)],
        }
    }

    /// The timer's prescaler (PSC): it counts at `timer_hz / (PSC + 1)`.
    pub fn prescaler(&self) -> u16 {
        self.prescaler
    }

    /// The timer writes for one step event: `step` the axes that step
    /// (`[pan, tilt]`), `dir_changed` whether a DIR pin changed in it
    /// (the rising edges then wait the DIR setup time). `None` when no
    /// axis steps: the timer is left alone.
    #[inline]
    pub fn event(&self, step: [bool; 2], dir_changed: bool) -> Option<OnePulse> {
        if !(step[0] || step[1]) {
            return None;
        }
        let mode = |on: bool| {
            if on {
                OCM_PWM_MODE_2
            } else {
                OCM_FORCE_INACTIVE
            }
        };
        let (compare, reload) = self.shapes[usize::from(dir_changed)];
        Some(OnePulse {
            ccmr1: mode(step[0]) << OCM_SHIFT[0] | mode(step[1]) << OCM_SHIFT[1],
            compare,
            reload,
        })
    }

    /// The duration of `counts` timer counts, ns, rounded down (for
    /// models of the timer's output).
    pub fn counts_ns(&self, counts: u32) -> u64 {
        let scaled = u64::from(counts) * (u64::from(self.prescaler) + 1) * 1_000_000_000;
        scaled / u64::from(self.timer_hz.max(1))
    }
}

#[cfg(test)]
mod tests;
