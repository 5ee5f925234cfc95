//! The circular buffers' layout and the half-buffer bookkeeping shared by
//! the refill (a task) and the DMA interrupt.
//!
//! Halves are counted from the start of the stream (wrapping `u32`,
//! from an even number): half `h` lives in physical half `h mod 2`. The interrupt counts the
//! halves the DMA has started; the refill keeps `written` (halves below it
//! are in the buffer) and, before storing a half, asks [`slot`] whether
//! its buffer is free yet or the DMA already began it (an underrun).
//! The DMA's own counter (NDTR) settles which half it reads right now,
//! even when the interrupt for a boundary it just crossed has not run
//! ([`Ring::reading_half`]).

use core::ops::Range;

/// Two halves of `half_len` samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ring {
    half_len: usize,
}

/// Where the refill stands with the half it writes next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slot {
    /// Its buffer still plays the half before: wait for the next boundary.
    Wait,
    /// The DMA reads the half before it: write it now.
    Free,
    /// The DMA already began it (and `halves - 1` more after it): those
    /// replay stale content; write the half after the one it reads.
    Late {
        /// Halves the DMA started before they were written.
        halves: u32,
    },
}

/// Signed distance `a - b` of two wrapping half counts.
const fn ahead(a: u32, b: u32) -> i32 {
    a.wrapping_sub(b) as i32
}

impl Ring {
    /// A ring of two halves of `half_len` samples (at least 1).
    pub const fn new(half_len: usize) -> Self {
        Self {
            half_len: if half_len == 0 { 1 } else { half_len },
        }
    }

    /// Samples per half.
    pub const fn half_len(&self) -> usize {
        self.half_len
    }

    /// Samples in the ring (the DMA's NDTR reload value).
    pub const fn samples(&self) -> usize {
        2 * self.half_len
    }

    /// Physical half (0 or 1) of half `h`.
    pub const fn physical(h: u32) -> usize {
        (h & 1) as usize
    }

    /// Buffer indices of physical half `physical` (0 or 1).
    pub fn range(&self, physical: usize) -> Range<usize> {
        let start = (physical & 1) * self.half_len;
        start..start + self.half_len
    }

    /// The index the DMA reads next, from NDTR (the items left before its
    /// circular reload: `len` at a half-0 start, 1 before the last item);
    /// `None` for a count this ring cannot show (a stopped or foreign
    /// stream).
    pub fn position(&self, ndtr: u32) -> Option<usize> {
        let ndtr = usize::try_from(ndtr).ok()?;
        (1..=self.samples())
            .contains(&ndtr)
            .then(|| self.samples() - ndtr)
    }

    /// The half the DMA reads now: `counted` is the half the interrupt last
    /// counted; when NDTR shows the other physical half, the DMA crossed a
    /// boundary whose interrupt has not run yet (it runs within
    /// microseconds, far less than a half). `None` for an invalid NDTR.
    pub fn reading_half(&self, counted: u32, ndtr: u32) -> Option<u32> {
        let physical = self.position(ndtr)? / self.half_len;
        Some(if physical == Self::physical(counted) {
            counted
        } else {
            counted.wrapping_add(1)
        })
    }

    /// Whether two streams fed by the same timer update are in lockstep:
    /// their positions differ by at most one item (the two DMA controllers
    /// serve the same update a few cycles apart), around the wrap too.
    pub fn in_lockstep(&self, ndtr_a: u32, ndtr_b: u32) -> bool {
        match (self.position(ndtr_a), self.position(ndtr_b)) {
            (Some(a), Some(b)) => {
                let d = a.abs_diff(b);
                d <= 1 || d == self.samples() - 1
            }
            _ => false,
        }
    }
}

/// Whether the half `next` can be written while the DMA reads `reading`.
pub const fn slot(next: u32, reading: u32) -> Slot {
    let lead = ahead(next, reading);
    if lead >= 2 {
        Slot::Wait
    } else if lead == 1 {
        Slot::Free
    } else {
        Slot::Late {
            halves: (1 - lead) as u32,
        }
    }
}

/// The interrupt's check as the DMA starts half `started`: an underrun
/// when the refill had not written it (`written` halves are), unless the
/// ring is `holding` one sample in both halves (replaying a hold is what
/// the loop asked for, however late).
pub const fn underrun_at_start(started: u32, written: u32, holding: bool) -> bool {
    !holding && ahead(started, written) >= 0
}

/// The refill's side of the bookkeeping: primes both halves, then claims
/// each next half as the DMA frees it and commits it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Cursor {
    /// The half written next.
    next: u32,
    /// Both halves were primed: the streams run.
    started: bool,
}

/// What [`Cursor::claim`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Claim {
    /// The half's buffer still plays: wait for the next boundary.
    Wait,
    /// Write physical half `physical` now; `late` halves were started by
    /// the DMA before they were written (0: in time).
    Write {
        /// The physical half (0 or 1).
        physical: usize,
        /// Halves the DMA replayed stale.
        late: u32,
    },
}

impl Cursor {
    /// Nothing written, streams stopped.
    pub const fn new() -> Self {
        Self {
            next: 0,
            started: false,
        }
    }

    /// Whether the streams run.
    pub const fn started(&self) -> bool {
        self.started
    }

    /// The physical half the next write goes to.
    pub const fn physical(&self) -> usize {
        Ring::physical(self.next)
    }

    /// Before the start: counts one primed half; `true` when both are and
    /// the streams start now (the DMA reads half 0, halves 0 and 1 are
    /// written: the interrupt's counts start at 0 and 2).
    pub fn primed(&mut self) -> bool {
        self.next += 1;
        self.started = self.next >= 2;
        self.started
    }

    /// While started, with the DMA reading `reading`: whether the next half
    /// may be written and where. When late, the next half becomes the one
    /// after the half the DMA reads.
    pub fn claim(&mut self, reading: u32) -> Claim {
        match slot(self.next, reading) {
            Slot::Wait => Claim::Wait,
            Slot::Free => Claim::Write {
                physical: self.physical(),
                late: 0,
            },
            Slot::Late { halves } => {
                self.next = reading.wrapping_add(1);
                Claim::Write {
                    physical: self.physical(),
                    late: halves,
                }
            }
        }
    }

    /// The claimed half is written (or a hold left as it is): the value of
    /// `written` for the interrupt, to store before [`Self::check`].
    pub fn commit(&mut self) -> u32 {
        self.next = self.next.wrapping_add(1);
        self.next
    }

    /// After [`Self::commit`] was published, with the DMA now reading
    /// `reading`: whether it had already begun the committed half (the
    /// copy finished too late; it started partly stale).
    pub const fn check(&self, reading: u32) -> bool {
        ahead(reading, self.next.wrapping_sub(1)) >= 0
    }

    /// The streams stopped (a fault): prime again.
    pub fn reset(&mut self) {
        *self = Self::new();
    }
}

#[cfg(test)]
mod tests;
