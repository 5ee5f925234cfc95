//! [`ServoIdSet`]: a set of servo bus ids without allocation.

/// A set of servo bus ids (0..=255), e.g. the servos known faulty.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ServoIdSet([u32; 8]);

impl ServoIdSet {
    /// The empty set.
    pub const fn new() -> Self {
        Self([0; 8])
    }

    fn word_bit(id: u8) -> (usize, u32) {
        (usize::from(id / 32), 1u32 << (id % 32))
    }

    /// Adds `id`.
    pub fn insert(&mut self, id: u8) {
        let (w, bit) = Self::word_bit(id);
        if let Some(word) = self.0.get_mut(w) {
            *word |= bit;
        }
    }

    /// Removes `id`.
    pub fn remove(&mut self, id: u8) {
        let (w, bit) = Self::word_bit(id);
        if let Some(word) = self.0.get_mut(w) {
            *word &= !bit;
        }
    }

    /// Whether `id` is in the set.
    pub fn contains(&self, id: u8) -> bool {
        let (w, bit) = Self::word_bit(id);
        self.0.get(w).is_some_and(|word| word & bit != 0)
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.0.iter().all(|w| *w == 0)
    }

    /// The smallest id in the set.
    pub fn first(&self) -> Option<u8> {
        self.iter().next()
    }

    /// The ids in the set, ascending.
    pub fn iter(&self) -> impl Iterator<Item = u8> + '_ {
        (0..=u8::MAX).filter(|id| self.contains(*id))
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use std::vec::Vec;

    use super::*;

    #[test]
    fn ids_go_in_and_out_across_the_words() {
        let mut set = ServoIdSet::new();
        assert!(set.is_empty());
        assert_eq!(set.first(), None);
        for id in [255, 0, 31, 32, 1] {
            set.insert(id);
        }
        assert_eq!(set.iter().collect::<Vec<_>>(), [0, 1, 31, 32, 255]);
        assert!(set.contains(32) && !set.contains(33));
        set.remove(0);
        set.remove(7);
        assert_eq!(set.first(), Some(1));
        for id in [1, 31, 32, 255] {
            set.remove(id);
        }
        assert!(set.is_empty());
    }
}
