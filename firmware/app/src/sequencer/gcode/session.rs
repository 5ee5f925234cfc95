//! The session's own moves on its state: the line waiting for room,
//! `$C`, the parser's position synced at rest.

use crate::grbl::GrblError;
use crate::sequencer::gcode::queue::PLANNER_BLOCKS;
use crate::sequencer::gcode::report;
use crate::sequencer::gcode::{GcodeSession, GrblMode};
use crate::sequencer::io::ActionSink;

impl GcodeSession {
    /// Moves the blocks of the line waiting for room into the queue when
    /// they fit, and answers it.
    pub(in crate::sequencer) fn take_owed(&mut self, out: &mut dyn ActionSink) {
        let motion = &mut self.motion;
        let Some(blocks) = motion.owed.as_ref() else {
            return;
        };
        if PLANNER_BLOCKS - motion.queue.len() < blocks.len() {
            return;
        }
        for block in motion.owed.take().into_iter().flatten() {
            // Room was checked above.
            let _ = self.motion.queue.push_back(block);
        }
        report::ok(out);
    }

    /// `$C`: toggles check mode (only when idle; leaving it resets the
    /// parser, as grbl does).
    pub(in crate::sequencer) fn check_mode(&mut self, idle: bool, out: &mut dyn ActionSink) {
        match self.mode {
            GrblMode::Check => {
                self.mode = GrblMode::Normal;
                self.parser.soft_reset();
                self.sync_position();
                report::notice(out, format_args!("MSG:Disabled"));
            }
            GrblMode::Normal if idle => {
                self.mode = GrblMode::Check;
                report::notice(out, format_args!("MSG:Enabled"));
            }
            _ => return report::error(out, GrblError::NotIdle),
        }
        report::ok(out);
    }

    /// The parser continues from where the spot is (after a stop, a
    /// reset or a jog cancel).
    pub(in crate::sequencer) fn sync_position(&mut self) {
        if self.motion.is_idle() {
            self.parser.position = self.motion.position;
        }
    }
}
