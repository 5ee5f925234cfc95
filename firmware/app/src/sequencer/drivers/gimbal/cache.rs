//! The joint degrees per mm of the blocks the stream plans, worked out
//! once per block (three aims through the f64 IK, ~85 000 M4
//! instructions) when it is queued or first planned, not every period.

use crate::sequencer::drivers::gimbal::deg_per_mm::DegPerMm;
use crate::sequencer::drivers::gimbal::plan::joint_deg_per_mm;
use crate::sequencer::drivers::gimbal::{PLAN_BLOCKS, Stream};
use crate::sequencer::drivers::stage::Stage;
use crate::sequencer::gcode::queue::planned_length;

impl Stream {
    /// Keeps the joint degrees per mm of the blocks the stream's next plan
    /// looks at (the running block and the queued motion blocks behind it,
    /// as the exit speed's plan walks them), working out only those not
    /// kept yet.
    #[inline(never)]
    pub(in crate::sequencer) fn remember(&mut self, st: &Stage) {
        let motion = &st.gcode.motion;
        let mut kept = DegPerMm::<PLAN_BLOCKS>::new();
        let mut lit = None;
        let running = motion.current.map(|c| c.block);
        for block in running.iter().chain(motion.queue.iter()) {
            let Some(length) = planned_length(block) else {
                break;
            };
            let block_lit = st.lights(block);
            if kept.is_full() || (block_lit && lit == Some(false)) {
                break;
            }
            lit = Some(block_lit);
            let v = joint_deg_per_mm(st, &self.deg_per_mm, block, length);
            if !kept.push(block, v) {
                break;
            }
        }
        self.deg_per_mm = kept;
    }
}
