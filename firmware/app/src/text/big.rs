//! Unsigned big integers of a fixed size, just what exact decimal ↔
//! binary conversion needs ([`super::decimal`], [`super::Shortest`]).

use core::cmp::Ordering;

/// Limbs: the largest number the decimal reader (10^452 · 2^66, the
/// smallest value's divisor shifted for a 66-bit quotient: 1 568 bits) and
/// the shortest-form writer (about 1 160 bits) hold.
const LIMBS: usize = 52;

/// An unsigned integer of `LIMBS` 32-bit limbs, least significant first.
#[derive(Clone, Copy)]
pub(super) struct Big(pub(super) [u32; LIMBS]);

impl Big {
    pub(super) const ZERO: Self = Self([0; LIMBS]);

    /// Limbs up to the highest non-zero one and one more (room for a
    /// carry): what the arithmetic below walks, not all `LIMBS`.
    fn active(&self) -> usize {
        self.0
            .iter()
            .rposition(|l| *l != 0)
            .map_or(1, |top| (top + 2).min(LIMBS))
    }

    pub(super) fn mul_add(&mut self, factor: u32, addend: u32) {
        let mut carry = u64::from(addend);
        let active = self.active();
        for limb in &mut self.0[..active] {
            let v = u64::from(*limb) * u64::from(factor) + carry;
            *limb = v as u32;
            carry = v >> 32;
        }
    }

    pub(super) fn bits(&self) -> i32 {
        match self.0.iter().rposition(|l| *l != 0) {
            Some(top) => (top as i32 + 1) * 32 - self.0[top].leading_zeros() as i32,
            None => 0,
        }
    }

    pub(super) fn shl(&mut self, bits: u32) {
        let (limbs, bits) = ((bits / 32) as usize, bits % 32);
        for i in (0..LIMBS).rev() {
            let hi = if i >= limbs { self.0[i - limbs] } else { 0 };
            let lo = if i > limbs { self.0[i - limbs - 1] } else { 0 };
            self.0[i] = if bits == 0 {
                hi
            } else {
                (hi << bits) | (lo >> (32 - bits))
            };
        }
    }

    pub(super) fn shr1(&mut self) {
        for i in 0..LIMBS {
            let next = if i + 1 < LIMBS { self.0[i + 1] } else { 0 };
            self.0[i] = (self.0[i] >> 1) | (next << 31);
        }
    }

    /// `value` as a big integer.
    pub(super) fn from_u64(value: u64) -> Self {
        let mut big = Self::ZERO;
        big.0[0] = value as u32;
        big.0[1] = (value >> 32) as u32;
        big
    }

    /// `self + other` (no overflow within the sizes used).
    pub(super) fn plus(&self, other: &Self) -> Self {
        let mut sum = Self::ZERO;
        let mut carry = 0u64;
        let active = self.active().max(other.active());
        let limbs = sum.0[..active]
            .iter_mut()
            .zip(self.0.iter())
            .zip(other.0.iter());
        for ((s, a), b) in limbs {
            let v = u64::from(*a) + u64::from(*b) + carry;
            *s = v as u32;
            carry = v >> 32;
        }
        sum
    }

    /// Numeric order.
    pub(super) fn compare(&self, other: &Self) -> Ordering {
        self.0.iter().rev().cmp(other.0.iter().rev())
    }

    /// `self -= other` if `self >= other`; whether it did.
    pub(super) fn sub_if_ge(&mut self, other: &Self) -> bool {
        if self.compare(other) == Ordering::Less {
            return false;
        }
        let mut borrow = 0u64;
        let active = self.active();
        for (a, b) in self.0[..active].iter_mut().zip(other.0.iter()) {
            let v = u64::from(*a)
                .wrapping_sub(u64::from(*b))
                .wrapping_sub(borrow);
            *a = v as u32;
            borrow = (v >> 63) & 1;
        }
        true
    }
}
