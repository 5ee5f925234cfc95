//! Servo faults in the sequencer: which servos are known dead, what that
//! refuses, and when the gimbal laser may light again.
//!
//! A servo the servo task reported faulty stays dead until it answers
//! again (the servo task pings it every 500 ms and reports `Recovered`) or
//! both servos arrive at a move. While a configured servo is dead, every
//! command that would move the gimbal (`goto`, `grid`, `pattern` with the
//! gimbal as target) is refused with an error naming the servo and how to
//! recover; galvo-only runs do not need the servos and go on. After any
//! fault the gimbal laser stays dark until the first arrival is confirmed,
//! whatever the laser mode.

use super::machine::{ActionSink, Core};
use super::drivers::Driver;
use crate::command::Command;
use crate::servo::task::{ServoFault, ServoIdSet};
use crate::settings::Settings;
use crate::status::Phase;
use crate::text::{ReplyText, reply_text};

/// Fault bookkeeping of the sequencer.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct ServoFaults {
    /// Servos known dead.
    dead: ServoIdSet,
    /// A fault happened and no arrival has been confirmed since.
    awaiting_arrival: bool,
}

impl ServoFaults {
    /// Servo `id` was reported faulty.
    pub(super) fn mark_dead(&mut self, id: u8) {
        self.dead.insert(id);
        self.awaiting_arrival = true;
    }

    /// Servo `id` answers again.
    pub(super) fn recovered(&mut self, id: u8) {
        self.dead.remove(id);
    }

    /// Both configured servos arrived at a move: alive, arrival confirmed.
    pub(super) fn arrived(&mut self, yaw_id: u8, pitch_id: u8) {
        self.dead.remove(yaw_id);
        self.dead.remove(pitch_id);
        self.awaiting_arrival = false;
    }

    /// The first of the configured servos that is dead.
    pub(super) fn dead_among(&self, yaw_id: u8, pitch_id: u8) -> Option<u8> {
        [yaw_id, pitch_id]
            .into_iter()
            .find(|id| self.dead.contains(*id))
    }

    /// The lowest dead servo id (for `status` and the fault LED).
    pub(super) fn first_dead(&self) -> Option<u8> {
        self.dead.first()
    }

    /// Whether the gimbal laser must stay dark: a configured servo is dead,
    /// or since the last fault no arrival was confirmed yet (`phase` is
    /// the run's phase).
    pub(super) fn gimbal_laser_blocked(
        &self,
        yaw_id: u8,
        pitch_id: u8,
        phase: Option<Phase>,
    ) -> bool {
        self.dead_among(yaw_id, pitch_id).is_some()
            || (self.awaiting_arrival && !matches!(phase, Some(Phase::Dwelling | Phase::Holding)))
    }
}

/// The configured servo ranges `(min, max)` of yaw and pitch, 0.1° (the
/// servo task's plausibility filter rejects readings outside).
pub(super) fn servo_ranges_tenths(settings: &Settings) -> [(i16, i16); 2] {
    // The limits are within ±180° (their parameter ranges): the casts are
    // exact.
    let tenths = |deg: f64| libm::round(deg * 10.0) as i16;
    [
        (tenths(settings.yaw.min_deg), tenths(settings.yaw.max_deg)),
        (
            tenths(settings.pitch.min_deg),
            tenths(settings.pitch.max_deg),
        ),
    ]
}

impl Core {
    /// The servo task reports servo `id` answering again.
    pub(super) fn servo_recovered(&mut self, id: u8, out: &mut dyn ActionSink) {
        self.faults.recovered(id);
        // As u32: the u8 writer is not linked (text::Int).
        let id = u32::from(id);
        self.notify(out, format_args!("info: servo {id} answering again"));
    }

    /// The servo task reports a fault of servo `id` during move `seq` (or
    /// found by its health check after move `seq`).
    pub(super) fn servo_fault(
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
    pub(super) fn refusal_for_dead_servo(&self, command: &Command) -> Option<ReplyText> {
        let moves_gimbal = matches!(
            command,
            Command::Goto(_) | Command::Grid { .. } | Command::Pattern { .. }
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
