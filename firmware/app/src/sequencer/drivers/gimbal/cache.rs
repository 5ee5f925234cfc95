//! The joint degrees per mm of the blocks the stream plans, worked out
//! once per block (three aims through the f64 IK, ~100 000 M4
//! instructions) when it is queued or first planned, not every period.

use crate::grbl::Block;
use crate::sequencer::drivers::gimbal::PLAN_BLOCKS;
use crate::sequencer::gcode::queue::planned_length;
use crate::sequencer::machine::Core;

/// A block's geometry, exactly (bits of its ends, and of an arc's centre
/// and sweep): blocks with the same key have the same joint travel.
type Key = [u64; 7];

/// The figures of the blocks last planned (the running one and those
/// behind it the plan looks at), with their keys.
#[derive(Debug, Clone)]
pub(in crate::sequencer) struct DegPerMm {
    entries: [(Key, f64); PLAN_BLOCKS],
    len: usize,
}

impl DegPerMm {
    pub(in crate::sequencer) const fn new() -> Self {
        Self {
            entries: [([0; 7], 0.0); PLAN_BLOCKS],
            len: 0,
        }
    }

    /// Forgets every figure (the geometry changed).
    pub(in crate::sequencer) fn clear(&mut self) {
        self.len = 0;
    }

    /// The figure kept for `block`, °/mm.
    pub(super) fn get(&self, block: &Block) -> Option<f64> {
        let key = key(block)?;
        self.entries
            .get(..self.len)?
            .iter()
            .find(|(k, _)| *k == key)
            .map(|&(_, v)| v)
    }
}

fn key(block: &Block) -> Option<Key> {
    let bits = |v: f64| v.to_bits();
    Some(match *block {
        Block::Rapid { from, to } | Block::Line { from, to, .. } | Block::Jog { from, to, .. } => [
            bits(from.x_mm),
            bits(from.y_mm),
            bits(to.x_mm),
            bits(to.y_mm),
            0,
            0,
            u64::MAX,
        ],
        Block::Arc { arc, .. } => [
            bits(arc.from.x_mm),
            bits(arc.from.y_mm),
            bits(arc.to.x_mm),
            bits(arc.to.y_mm),
            bits(arc.centre.x_mm),
            bits(arc.centre.y_mm),
            bits(arc.sweep_rad),
        ],
        _ => return None,
    })
}

impl Core {
    /// Keeps the joint degrees per mm of the blocks the stream's next plan
    /// looks at (the running block and the queued motion blocks behind it,
    /// as [`Core::stream_exit_speed`] walks them), working out only those
    /// not kept yet.
    #[inline(never)]
    pub(in crate::sequencer) fn stream_remember(&mut self) {
        if !self.gcode_streams() {
            return;
        }
        let motion = &self.gcode.motion;
        let mut kept = DegPerMm::new();
        let mut lit = None;
        let running = motion.current.map(|c| c.block);
        for block in running.iter().chain(motion.queue.iter()) {
            let (Some(length), Some(key)) = (planned_length(block), key(block)) else {
                break;
            };
            let block_lit = self.lights(block);
            if kept.len == PLAN_BLOCKS || (block_lit && lit == Some(false)) {
                break;
            }
            lit = Some(block_lit);
            let v = match self.jobs.gimbal.deg_per_mm.get(block) {
                Some(v) => v,
                None => self.joint_deg_per_mm_aimed(block, length),
            };
            kept.entries[kept.len] = (key, v);
            kept.len += 1;
        }
        self.jobs.gimbal.deg_per_mm = kept;
    }
}
