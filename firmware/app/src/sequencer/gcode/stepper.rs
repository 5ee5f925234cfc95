//! The session's side of the stepper's G-code stage
//! ([`StepperJob`](crate::sequencer::drivers::stepper::StepperJob)):
//! blocks done, refusals into an alarm, the position synced at rest, and
//! the reply to `$H`.

use crate::grbl::{Alarm, GrblError};
use crate::sequencer::drivers::stepper::gcode::StepperReport;
use crate::sequencer::gcode::context::Session;
use crate::sequencer::gcode::report;
use crate::sequencer::gcode::{GcodeSession, GrblMode};
use crate::sequencer::io::ActionSink;
use crate::stepper::{HomingFailure, StepperEvent};

impl Session<'_> {
    /// Hands the current block to the stepper (or waits for rest first).
    pub(in crate::sequencer) fn stepper_send(&mut self, out: &mut dyn ActionSink) {
        self.with_stage(out, |st, jobs, out| jobs.stepper.send(st, out));
    }

    /// Tells the stepper task the feed override when it changed.
    pub(in crate::sequencer) fn stepper_override(&mut self, out: &mut dyn ActionSink) {
        let percent = self.gcode.overrides.feed;
        let stepping = self.drivers().hands_over_blocks();
        self.jobs.stepper.send_override(percent, stepping, out);
    }

    /// A report of the stepper task, when it is the G-code session's:
    /// `true` when it was the job's. The end of homing is noted either way.
    #[inline(never)]
    pub(in crate::sequencer) fn stepper_event(
        &mut self,
        event: &StepperEvent,
        out: &mut dyn ActionSink,
    ) -> bool {
        if let StepperEvent::Homed { .. } | StepperEvent::HomingFailed { .. } = event {
            *self.stepper_homing = false;
        }
        match self.with_stage(out, |st, jobs, out| jobs.stepper.event(st, event, out)) {
            StepperReport::Other => false,
            StepperReport::Handled => true,
            StepperReport::BlockDone => {
                self.stepper_block_done(out);
                true
            }
            StepperReport::Refused => {
                if let StepperEvent::Refused { why, .. } = event {
                    // The checks before it passed, the stepper refused it
                    // (its axes beyond their soft limits): as on the galvo.
                    report::notice(out, format_args!("MSG:stepper: move refused: {why:?}"));
                }
                self.alarm(Alarm::SoftLimit, out);
                true
            }
            StepperReport::AtRest => {
                self.gcode.sync_position();
                false
            }
        }
    }

    /// The end of homing (`failed`: why it failed), the axes at rest at
    /// `steps`: MPos where homing left the spot (a failed seek moved the
    /// axes too); when a `$H` waits, its reply — `ok` (unlocked) or, as
    /// grbl, `ALARM:N` (locked) and then `ok`; parameters that allow no
    /// homing: `error:5`.
    #[inline(never)]
    pub(in crate::sequencer) fn homing_done(
        &mut self,
        steps: [i32; 2],
        failed: Option<HomingFailure>,
        out: &mut dyn ActionSink,
    ) {
        if self.gcode.motion.is_idle() {
            self.with_stage(out, |st, jobs, _| jobs.stepper.at(st, steps));
            self.gcode.sync_position();
        }
        self.gcode.homing_done(failed, out);
    }

    /// The current block is done on the stepper's side.
    #[inline(never)]
    fn stepper_block_done(&mut self, out: &mut dyn ActionSink) {
        if let Some(c) = self.gcode.motion.current.as_mut() {
            c.stepper_seq = None;
        }
        self.step_done(out);
    }
}

impl GcodeSession {
    /// The end of homing (`failed`: why it failed) for the session: when a
    /// `$H` waits, its reply — `ok` (unlocked) or, as grbl, `ALARM:N`
    /// (locked) and then `ok`; parameters that allow no homing: `error:5`.
    fn homing_done(&mut self, failed: Option<HomingFailure>, out: &mut dyn ActionSink) {
        if !core::mem::take(&mut self.homing) {
            return;
        }
        let alarm = match failed {
            None => {
                self.mode = GrblMode::Normal;
                return report::ok(out);
            }
            Some(HomingFailure::NoSwitches | HomingFailure::BadConfig) => {
                return report::error(out, GrblError::HomingDisabled);
            }
            Some(HomingFailure::NotFound(_)) => Alarm::HomingNotFound,
            Some(HomingFailure::StillPressed(_)) => Alarm::HomingPullOff,
            Some(HomingFailure::Interrupted) => Alarm::HomingReset,
        };
        self.mode = GrblMode::Alarm;
        report::alarm(out, alarm);
        report::ok(out);
    }
}
