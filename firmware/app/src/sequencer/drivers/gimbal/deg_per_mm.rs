//! The joint degrees per mm the gimbal's stream keeps for the blocks it
//! plans (`cache.rs` works them out), under a 64-bit hash of each block's
//! geometry: 16 bytes a block, for the core's copies on the stack count
//! against the tasks' frame ceilings. Two different blocks among the ≤ 2N
//! compared share a hash with odds below 1e-17.

use crate::grbl::Block;

/// The figures of the (at most `N`) blocks last planned, with their keys.
#[derive(Debug, Clone)]
pub(in crate::sequencer) struct DegPerMm<const N: usize>(heapless::Vec<(u64, f64), N>);

impl<const N: usize> DegPerMm<N> {
    /// Nothing kept.
    pub(in crate::sequencer) const fn new() -> Self {
        Self(heapless::Vec::new())
    }

    /// Forgets every figure (the geometry changed).
    pub(in crate::sequencer) fn clear(&mut self) {
        self.0.clear();
    }

    /// The figure kept for `block`, °/mm.
    pub(in crate::sequencer) fn get(&self, block: &Block) -> Option<f64> {
        let key = key(block)?;
        self.0.iter().find(|(k, _)| *k == key).map(|&(_, v)| v)
    }

    /// Keeps `v` for `block` (`false`: full, or not a motion block).
    pub(in crate::sequencer) fn push(&mut self, block: &Block, v: f64) -> bool {
        key(block).is_some_and(|key| self.0.push((key, v)).is_ok())
    }

    /// Whether `N` figures are kept.
    pub(in crate::sequencer) fn is_full(&self) -> bool {
        self.0.is_full()
    }
}

/// The hash of a motion block's geometry (the bits of its ends, and of an
/// arc's centre and sweep): blocks alike in it have the same joint travel.
fn key(block: &Block) -> Option<u64> {
    let words = match *block {
        Block::Rapid { from, to } | Block::Line { from, to, .. } | Block::Jog { from, to, .. } => {
            [from.x_mm, from.y_mm, to.x_mm, to.y_mm, 0.0, 0.0, f64::NAN]
        }
        Block::Arc { arc, .. } => [
            arc.from.x_mm,
            arc.from.y_mm,
            arc.to.x_mm,
            arc.to.y_mm,
            arc.centre.x_mm,
            arc.centre.y_mm,
            arc.sweep_rad,
        ],
        _ => return None,
    };
    Some(
        words
            .iter()
            .fold(0x9E37_79B9_7F4A_7C15, |h, w| mix(h ^ w.to_bits())),
    )
}

/// splitmix64's finalizer: every input bit moves every output bit.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
