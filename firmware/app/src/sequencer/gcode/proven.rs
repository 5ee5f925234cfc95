//! What the core keeps of the soft-limit check's fast path (`reach.rs`):
//! per driver, the fraction of the board proven reachable with the
//! current geometry. A few bytes: the core's copies on the stack count
//! against the tasks' frame ceilings.

/// Fractions of the board tried, largest first.
pub(in crate::sequencer) const SCALES: [f64; 2] = [1.0, 0.5];

/// Per driver slot, 1 + the index in [`SCALES`] of the fraction of the
/// board (about its centre) proven reachable, 0 for none; all
/// [`u8::MAX`] before the first proof.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::sequencer) struct ProvenReach([u8; 3]);

impl ProvenReach {
    /// Not proven yet (the core proves it at its first event: proving in
    /// `Core::new` copied the core on its stack frame, 9 284 B).
    pub(in crate::sequencer) const UNPROVEN: Self = Self([u8::MAX; 3]);
    /// Nothing proven: every point takes the exact check.
    pub(in crate::sequencer) const NONE: Self = Self([0; 3]);

    /// This, or `prove()` when not proven yet.
    pub(in crate::sequencer) fn or_prove(self, prove: impl FnOnce() -> Self) -> Self {
        if self == Self::UNPROVEN {
            prove()
        } else {
            self
        }
    }

    /// The fraction of the board proven for driver slot `slot`.
    pub(in crate::sequencer) fn scale(&self, slot: usize) -> Option<f64> {
        let k = usize::from(*self.0.get(slot)?);
        SCALES.get(k.checked_sub(1)?).copied()
    }

    /// This with `scale` (an index in [`SCALES`]) for driver slot `slot`.
    pub(in crate::sequencer) fn with(mut self, slot: usize, scale: Option<usize>) -> Self {
        if let Some(s) = self.0.get_mut(slot) {
            *s = scale.map_or(0, |k| (k + 1).min(SCALES.len()) as u8);
        }
        self
    }
}
