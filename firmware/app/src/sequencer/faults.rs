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

use crate::servo::task::ServoIdSet;
use crate::settings::Settings;
use crate::status::Phase;

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

mod servo;
