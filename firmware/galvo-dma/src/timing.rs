//! The sample clock (TIM8's prescaler and reload) and the refill time
//! measured with the CPU's cycle counter.

/// TIM8's prescaler and auto-reload: one update every
/// `(prescaler + 1) · (reload + 1)` timer clocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TimerSetting {
    /// PSC register value (divides by `prescaler + 1`).
    pub prescaler: u16,
    /// ARR register value (counts `reload + 1` prescaled ticks).
    pub reload: u16,
}

impl TimerSetting {
    /// Timer clocks per update.
    pub const fn period_ticks(&self) -> u32 {
        (self.prescaler as u32 + 1) * (self.reload as u32 + 1)
    }

    /// The update period, s, at timer clock `timer_hz`.
    pub fn period_s(&self, timer_hz: u32) -> f64 {
        f64::from(self.period_ticks()) / f64::from(timer_hz.max(1))
    }
}

/// The setting nearest to `period_s` (s) at timer clock `timer_hz`: the
/// smallest prescaler whose reload fits 16 bits (finest resolution), the
/// reload rounded to the nearest tick (within half a prescaled tick
/// and half a timer clock). `None` when the period is not a
/// positive finite number, shorter than 2 timer clocks or longer than
/// 2³² of them.
pub fn timer_setting(timer_hz: u32, period_s: f64) -> Option<TimerSetting> {
    let ticks = period_s * f64::from(timer_hz);
    if !ticks.is_finite() || !(2.0..=f64::from(u32::MAX)).contains(&ticks) {
        return None;
    }
    // Whole timer clocks (no_std: round by hand; positive here).
    let ticks = (ticks + 0.5) as u32;
    // Divide by `div` so that at most 65 536 counts remain per update.
    let div = ticks.div_ceil(65_536);
    let counts = ((ticks + div / 2) / div).clamp(1, 65_536);
    Some(TimerSetting {
        prescaler: u16::try_from(div - 1).ok()?,
        reload: (counts - 1) as u16,
    })
}

/// The worst refill since the stream started, in CPU cycles: the loop's
/// own time between two hand-overs (computing the next half after it got
/// control back) plus the copy into the DMA buffer; the wait for the free
/// half is not counted. Readings are a free-running wrapping `u32` cycle
/// counter (the DWT's CYCCNT wraps every 25.6 s at 168 MHz, far longer
/// than a refill).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RefillMeter {
    last_return: Option<u32>,
    worst: Option<u32>,
}

impl RefillMeter {
    /// Nothing measured yet.
    pub const fn new() -> Self {
        Self {
            last_return: None,
            worst: None,
        }
    }

    /// One hand-over: the loop called in at `entered`, the free half was
    /// there at `copy_from`, and the loop got control back at `returned`.
    /// Returns this refill's cycles (`None` for the first hand-over: the
    /// loop's start-up is not a refill).
    pub fn record(&mut self, entered: u32, copy_from: u32, returned: u32) -> Option<u32> {
        let refill = self.last_return.map(|last| {
            entered
                .wrapping_sub(last)
                .saturating_add(returned.wrapping_sub(copy_from))
        });
        self.last_return = Some(returned);
        if let Some(cycles) = refill {
            self.worst = Some(self.worst.map_or(cycles, |w| w.max(cycles)));
        }
        refill
    }

    /// The worst refill so far, cycles.
    pub const fn worst(&self) -> Option<u32> {
        self.worst
    }
}

#[cfg(test)]
mod tests;
