//! The prepared steps, in place: a step's plans (a few KB with its
//! stroke) are written once by the prep stage and used where they lie by
//! the refill, never copied in it.

use super::state::{PREP_DEPTH, Prepared};

/// Slots: the running step and [`PREP_DEPTH`] prepared ones.
const SLOTS: usize = PREP_DEPTH + 1;

/// A ring of prepared steps, oldest first.
pub(super) struct StepRing {
    slots: [Option<Prepared>; SLOTS],
    head: usize,
    len: usize,
}

impl StepRing {
    /// Empty. Each slot is set to `None` where it lies (its tag only), not
    /// copied from a constant image of a few KB in flash per slot.
    pub(super) fn new() -> Self {
        Self {
            slots: core::array::from_fn(|_| None),
            head: 0,
            len: 0,
        }
    }

    /// Steps held.
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// The `i`-th step, oldest first.
    pub(super) fn get(&self, i: usize) -> Option<&Prepared> {
        if i >= self.len {
            return None;
        }
        self.slots.get((self.head + i) % SLOTS)?.as_ref()
    }

    /// The `i`-th step, oldest first.
    pub(super) fn get_mut(&mut self, i: usize) -> Option<&mut Prepared> {
        if i >= self.len {
            return None;
        }
        self.slots.get_mut((self.head + i) % SLOTS)?.as_mut()
    }

    /// The newest step.
    pub(super) fn back(&self) -> Option<&Prepared> {
        self.get(self.len.checked_sub(1)?)
    }

    /// Appends a step; `false` (dropped) when full.
    pub(super) fn push_back(&mut self, step: Prepared) -> bool {
        if self.len >= SLOTS {
            return false;
        }
        match self.slots.get_mut((self.head + self.len) % SLOTS) {
            Some(slot) => {
                *slot = Some(step);
                self.len += 1;
                true
            }
            None => false,
        }
    }

    /// Drops the oldest step (in place: no copy).
    pub(super) fn drop_front(&mut self) {
        if self.len > 0 {
            if let Some(slot) = self.slots.get_mut(self.head) {
                *slot = None;
            }
            self.head = (self.head + 1) % SLOTS;
            self.len -= 1;
        }
    }

    /// Drops every step.
    pub(super) fn clear(&mut self) {
        while self.len > 0 {
            self.drop_front();
        }
    }
}
