//! The one fixed-capacity ring of the motion pipeline: the look-ahead
//! planner's blocks, the stepper's prepared segments (pushed by the prep
//! task, popped in the step interrupt) and the galvo loop's prepared
//! steps (a few KB each).
//!
//! An own type, not `heapless::Deque` (which laser-app uses for its byte
//! and message queues), for two measured reasons (`cargo xtask bench-m4`,
//! M4 instructions, with `Deque` in its place): a `Deque` drops its front
//! only by moving it out, which copied a prepared galvo step (~2 KB) at
//! every step start (a jump's refill 9 560 → 11 400, a line's 30 400 →
//! 33 400, a joined stroke's prep 21 320 → 26 080), and its `Drop` gives
//! everything holding one drop glue. Here a slot is an `Option` (no extra
//! bytes where `T` has a niche): [`Ring::drop_front`] clears it where it
//! lies, and the ring wraps by compare (no division in the interrupt).
//! Its accessors are `#[inline(always)]`: laser-app is built for size,
//! where a plain `#[inline]` left them out of line in the planner's
//! passes.
//!
//! The capacity `N` must be at least 1 (checked at compile time):
//!
//! ```compile_fail
//! let _ = kinematics_core::ring::Ring::<u8, 0>::new();
//! ```

/// Up to `N` items, oldest first.
#[derive(Debug, Clone)]
pub struct Ring<T, const N: usize> {
    slots: [Option<T>; N],
    head: usize,
    len: usize,
}

impl<T, const N: usize> Default for Ring<T, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T, const N: usize> Ring<T, N> {
    const CAPACITY_OK: () = assert!(N > 0, "a Ring needs N >= 1");

    /// Empty (usable in a `static`).
    pub const fn new() -> Self {
        let () = Self::CAPACITY_OK;
        Self {
            slots: [const { None }; N],
            head: 0,
            len: 0,
        }
    }

    /// Items held.
    #[inline]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether it holds nothing.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Whether nothing more fits.
    #[inline]
    pub fn is_full(&self) -> bool {
        self.len == N
    }

    /// The slot of the `i`-th item (`i < N`).
    #[inline(always)]
    fn slot(&self, i: usize) -> usize {
        let p = self.head + i;
        if p >= N { p - N } else { p }
    }

    /// The `i`-th item, oldest first.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Option<&T> {
        if i >= self.len {
            return None;
        }
        self.slots.get(self.slot(i))?.as_ref()
    }

    /// The `i`-th item, oldest first.
    #[inline(always)]
    pub fn get_mut(&mut self, i: usize) -> Option<&mut T> {
        if i >= self.len {
            return None;
        }
        let slot = self.slot(i);
        self.slots.get_mut(slot)?.as_mut()
    }

    /// The oldest item.
    #[inline]
    pub fn front(&self) -> Option<&T> {
        self.get(0)
    }

    /// The newest item.
    #[inline]
    pub fn back(&self) -> Option<&T> {
        self.get(self.len.checked_sub(1)?)
    }

    /// The newest item.
    #[inline]
    pub fn back_mut(&mut self) -> Option<&mut T> {
        self.get_mut(self.len.checked_sub(1)?)
    }

    /// Appends `item`; gives it back when full.
    #[inline(always)]
    pub fn push_back(&mut self, item: T) -> Result<(), T> {
        if self.len == N {
            return Err(item);
        }
        let slot = self.slot(self.len);
        match self.slots.get_mut(slot) {
            Some(s) => {
                *s = Some(item);
                self.len += 1;
                Ok(())
            }
            None => Err(item),
        }
    }

    /// Takes the oldest item out.
    #[inline(always)]
    pub fn pop_front(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        let item = self.slots.get_mut(self.head)?.take();
        self.advance();
        item
    }

    /// Drops the oldest item where it lies (nothing is moved).
    #[inline]
    pub fn drop_front(&mut self) {
        if self.len == 0 {
            return;
        }
        if let Some(s) = self.slots.get_mut(self.head) {
            *s = None;
        }
        self.advance();
    }

    /// The front slot is free: the next one is the head.
    #[inline(always)]
    fn advance(&mut self) {
        self.head += 1;
        if self.head == N {
            self.head = 0;
        }
        self.len -= 1;
    }

    /// Drops every item.
    pub fn clear(&mut self) {
        while self.len > 0 {
            self.drop_front();
        }
        self.head = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wraps_keeps_order_and_refuses_when_full() {
        let mut r: Ring<u32, 3> = Ring::new();
        assert!(r.is_empty() && r.pop_front().is_none() && r.back().is_none());
        for round in 0..5u32 {
            for k in 0..3 {
                assert_eq!(r.push_back(10 * round + k), Ok(()));
            }
            assert!(r.is_full());
            assert_eq!(r.push_back(99), Err(99));
            assert_eq!(r.get(3), None);
            assert_eq!(
                (r.front(), r.back()),
                (Some(&(10 * round)), Some(&(10 * round + 2)))
            );
            if let Some(b) = r.back_mut() {
                *b += 1;
            }
            assert_eq!(r.pop_front(), Some(10 * round));
            r.drop_front();
            assert_eq!(r.get(0), Some(&(10 * round + 3)));
            assert_eq!(r.len(), 1);
            r.drop_front();
            assert!(r.is_empty());
        }
    }

    #[test]
    fn clear_empties_and_the_ring_is_reused() {
        let mut r: Ring<[u8; 4], 2> = Ring::default();
        r.push_back([1; 4]).unwrap();
        r.push_back([2; 4]).unwrap();
        r.drop_front();
        r.push_back([3; 4]).unwrap();
        r.clear();
        assert!(r.is_empty() && r.get(0).is_none());
        r.push_back([4; 4]).unwrap();
        if let Some(x) = r.get_mut(0) {
            x[0] = 5;
        }
        assert_eq!(r.get(0), Some(&[5, 4, 4, 4]));
    }
}
