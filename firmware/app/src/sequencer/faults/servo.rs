//! What a servo fault does to the run and to the commands that need the servos.

use crate::command::Command;
use crate::sequencer::drivers::Driver;
use crate::sequencer::machine::{ActionSink, Core};
use crate::servo::task::ServoFault;
use crate::text::{ReplyText, reply_text};

impl Core {
    /// The servo task reports servo `id` answering again.
    pub(in crate::sequencer) fn servo_recovered(&mut self, id: u8, out: &mut dyn ActionSink) {
        self.faults.recovered(id);
        // As u32: the u8 writer is not linked (text::Int).
        let id = u32::from(id);
        self.notify(out, format_args!("info: servo {id} answering again"));
    }

    /// The servo task reports a fault of servo `id` during move `seq` (or
    /// found by its health check after move `seq`).
    pub(in crate::sequencer) fn servo_fault(
        &mut self,
        seq: u32,
        id: u8,
        fault: ServoFault,
        out: &mut dyn ActionSink,
    ) {
        // What a fault says about the servo is never stale: it is dead
        // until it answers again.
        self.faults.mark_dead(id);
        let gimbal_run = self.drivers().any(Driver::needs_servos) && self.run.is_some();
        // A fault of an older, superseded move: the current move finds out
        // itself (the laser is dark meanwhile: the servo is marked dead).
        if gimbal_run
            && self
                .run
                .is_some_and(|r| r.seq != seq && r.phase.is_travel())
        {
            return;
        }
        let id = u32::from(id);
        if gimbal_run {
            self.notify(
                out,
                format_args!("error: servo {id} fault ({fault:?}); pattern stopped, laser off"),
            );
            self.stop("servo fault", out);
        } else {
            // Idle, or a galvo-only run that does not need the servos.
            self.notify(
                out,
                format_args!(
                    "error: servo {id} fault ({fault:?}); gimbal commands refused until it answers"
                ),
            );
        }
    }

    /// The refusal for `command` when it needs a servo known dead.
    pub(in crate::sequencer) fn refusal_for_dead_servo(
        &self,
        command: &Command,
    ) -> Option<ReplyText> {
        let moves_gimbal = matches!(
            command,
            Command::Goto(_)
                | Command::Grid { .. }
                | Command::Pattern { .. }
                | Command::Preset(crate::command::PresetCommand::Goto(_))
        ) && self.drivers().any(Driver::needs_servos);
        if !moves_gimbal {
            return None;
        }
        let id = self
            .faults
            .dead_among(self.settings.yaw.id, self.settings.pitch.id)
            .map(u32::from)?;
        Some(reply_text(format_args!(
            "servo {id} not responding: check its power and cable; pinged every 0.5 s, \
             wait for [info: servo {id} answering again]"
        )))
    }
}
