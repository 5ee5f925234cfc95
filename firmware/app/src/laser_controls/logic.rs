//! The laser controls' pure state machine: input debouncing, the latch,
//! the manual reset and the emission indicator's lead time. No clock and
//! no I/O: time arrives with every call (µs since boot).
//!
//! ```text
//!            interlock open or key off (at once, any state)
//!   ┌──────────────────────────────────────────────────────┐
//!   ▼                                                      │
//! Latched ──arm (interlock closed, key on)──▶ Arming ──delay──▶ Armed
//! (power-up,                                  indicator on,    indicator on,
//!  no emission)                               no emission      emission possible
//! ```
//!
//! Debouncing is asymmetric, in the safe direction: a raw reading of
//! "open" (interlock) or "off" (key) counts at once — a bounce can only
//! darken the laser —; "closed" / "on" counts only once it has read so for
//! [`SETTLE_US`] without a break.

/// How long an input must read closed (interlock) or on (key) without a
/// break before it counts as such, µs.
pub const SETTLE_US: u64 = 20_000;

/// The raw levels of the two inputs, as read from the pins.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ControlInputs {
    /// The remote interlock loop is closed (its terminals joined).
    pub interlock_closed: bool,
    /// The key switch is on.
    pub key_on: bool,
}

/// Why emission is latched off.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LatchCause {
    /// Not armed since power-up.
    PowerUp,
    /// The remote interlock opened.
    InterlockOpened,
    /// The key switch was turned off.
    KeyOff,
}

impl LatchCause {
    /// Words for `status` and notices.
    pub fn describe(self) -> &'static str {
        match self {
            LatchCause::PowerUp => "not armed since power-up",
            LatchCause::InterlockOpened => "latched: the interlock opened",
            LatchCause::KeyOff => "latched: the key switch was off",
        }
    }
}

/// Where the controls are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Arming {
    /// No emission until the interlock is closed, the key on and `arm`
    /// typed.
    Latched(LatchCause),
    /// Armed; the emission indicator is on and emission becomes possible
    /// at `ready_at_us`.
    Arming {
        /// When emission becomes possible, µs since boot.
        ready_at_us: u64,
    },
    /// Emission possible; the emission indicator is on.
    Armed,
}

/// Why `arm` was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ArmRefusal {
    /// The interlock reads open (or has not read closed for
    /// [`SETTLE_US`] yet).
    InterlockOpen,
    /// The key switch is off (or has not read on for [`SETTLE_US`] yet).
    KeyOff,
}

impl ArmRefusal {
    /// The error text.
    pub fn describe(self) -> &'static str {
        match self {
            ArmRefusal::InterlockOpen => "interlock open: close it, then arm",
            ArmRefusal::KeyOff => "key switch off: turn it on, then arm",
        }
    }
}

/// One input's debouncer: open/off counts at once, closed/on after
/// [`SETTLE_US`] of unbroken readings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct Debounced {
    /// The debounced level (closed / on).
    level: bool,
    /// Since when the raw input reads closed/on without a break (while
    /// the debounced level is still open/off), µs.
    rising_since_us: Option<u64>,
}

impl Debounced {
    /// Takes a raw reading at `now_us`; returns the debounced level.
    fn sample(&mut self, now_us: u64, raw: bool) -> bool {
        if !raw {
            *self = Self::default();
        } else if !self.level {
            let since = *self.rising_since_us.get_or_insert(now_us);
            if now_us.saturating_sub(since) >= SETTLE_US {
                *self = Self {
                    level: true,
                    rising_since_us: None,
                };
            }
        }
        self.level
    }

    /// When a rising input will count, µs.
    fn settles_at_us(&self) -> Option<u64> {
        self.rising_since_us.map(|since| since + SETTLE_US)
    }
}

/// The laser controls' state (see the module docs). Starts latched
/// ([`LatchCause::PowerUp`]) with both inputs counted open/off.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ControlsLogic {
    interlock: Debounced,
    key: Debounced,
    arming: Arming,
}

impl Default for ControlsLogic {
    fn default() -> Self {
        Self::new()
    }
}

impl ControlsLogic {
    /// At power-up: latched, no emission.
    pub const fn new() -> Self {
        Self {
            interlock: Debounced {
                level: false,
                rising_since_us: None,
            },
            key: Debounced {
                level: false,
                rising_since_us: None,
            },
            arming: Arming::Latched(LatchCause::PowerUp),
        }
    }

    /// Takes the raw input levels read at `now_us` (µs since boot; never
    /// earlier than the previous call's). Opening the interlock or turning
    /// the key off latches emission off at once; an arming whose delay has
    /// passed becomes armed.
    pub fn sample(&mut self, now_us: u64, raw: ControlInputs) {
        let interlock = self.interlock.sample(now_us, raw.interlock_closed);
        let key = self.key.sample(now_us, raw.key_on);
        if !interlock {
            self.latch(LatchCause::InterlockOpened);
        } else if !key {
            self.latch(LatchCause::KeyOff);
        } else if let Arming::Arming { ready_at_us } = self.arming
            && now_us >= ready_at_us
        {
            self.arming = Arming::Armed;
        }
    }

    /// Latches emission off for `cause` (a power-up latch keeps its cause:
    /// the unit was never armed).
    fn latch(&mut self, cause: LatchCause) {
        if !matches!(self.arming, Arming::Latched(_)) {
            self.arming = Arming::Latched(cause);
        }
    }

    /// The manual reset at `now_us`: with the interlock closed and the key
    /// on (debounced), starts the emission indicator now and makes
    /// emission possible `delay_us` later. Already arming or armed: no
    /// change. Refused (nothing changes) otherwise.
    pub fn arm(&mut self, now_us: u64, delay_us: u64) -> Result<(), ArmRefusal> {
        if !self.interlock.level {
            return Err(ArmRefusal::InterlockOpen);
        }
        if !self.key.level {
            return Err(ArmRefusal::KeyOff);
        }
        if let Arming::Latched(_) = self.arming {
            self.arming = Arming::Arming {
                ready_at_us: now_us.saturating_add(delay_us),
            };
            if delay_us == 0 {
                self.arming = Arming::Armed;
            }
        }
        Ok(())
    }

    /// Where the controls are.
    pub fn arming(&self) -> Arming {
        self.arming
    }

    /// The debounced inputs.
    pub fn inputs(&self) -> ControlInputs {
        ControlInputs {
            interlock_closed: self.interlock.level,
            key_on: self.key.level,
        }
    }

    /// Whether the laser may emit: armed, the delay passed.
    pub fn emission_permitted(&self) -> bool {
        self.arming == Arming::Armed
    }

    /// Whether the emission indicator is on: from the manual reset (the
    /// delay's start) for as long as emission is possible.
    pub fn indicator_on(&self) -> bool {
        !matches!(self.arming, Arming::Latched(_))
    }

    /// The next time [`Self::sample`] changes something by time alone (an
    /// input settling, the delay ending), µs.
    pub fn next_deadline_us(&self) -> Option<u64> {
        let ready = match self.arming {
            Arming::Arming { ready_at_us } => Some(ready_at_us),
            _ => None,
        };
        [
            self.interlock.settles_at_us(),
            self.key.settles_at_us(),
            ready,
        ]
        .into_iter()
        .flatten()
        .min()
    }
}

#[cfg(test)]
mod tests;
