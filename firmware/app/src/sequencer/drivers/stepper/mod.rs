//! G-code on the stepper pan/tilt (`target stepper`): each block goes to
//! the stepper task as a move along its board line or arc (G0 as joint
//! travel), cut there within the stepper's line tolerance and planned by
//! its look-ahead planner. A block is handed on as soon as the stepper
//! has taken the one before ([`StepperEvent::Taken`]), so the planner
//! joins them at speed; the block before a change of the laser (dark ↔
//! lit, or of its M3/M4 and S), a dwell, a pause or the end waits for
//! rest, so the laser switches where the spot is (the stepper runs
//! several blocks ahead of the one the sequencer hands over). A feed hold decelerates along the path at the
//! limit (laser dark at once); `~` goes on from the point it stopped at:
//! the rest of the block it stopped in, then the queue.

use crate::domain::PointCm;
use crate::grbl::Laser;
use crate::settings::Settings;
use crate::stepper::StepperConfig;
use kinematics_core::frames::BoardPoint;
use kinematics_core::gimbal::{Gimbal, GimbalModel};

/// What the stepper has of the G-code job.
#[derive(Debug, Clone, Copy, Default)]
pub(in crate::sequencer) struct StepperJob {
    /// The last move handed over and not yet at rest.
    inflight: Option<u32>,
    /// The laser of the blocks handed over: lit, and with what setting.
    lit: bool,
    laser: Laser,
    /// The current block waits for rest before it is handed over.
    waiting: bool,
    /// A hold came to rest: `~` asks the stepper to go on with its moves.
    held: bool,
    /// A hold was asked and the stepper has not reported rest yet.
    braking: bool,
    /// The feed override the stepper task has, % (`None`: not sent since
    /// the last stop).
    feed_percent: Option<u8>,
    /// The step generator's speed over the running block's cruise speed,
    /// ‰ (the shell notes it before each event).
    pub(in crate::sequencer) speed_permille: u16,
}

impl StepperJob {
    /// Forgets the job (a stop, a reset).
    #[inline(never)]
    pub(in crate::sequencer) fn clear(&mut self) {
        *self = Self::default();
    }
}

/// The stepper parameters from `settings` (`stepper.*`), on the board
/// placed as the settings say (OQ, offsets, pose), exact model, OL = 0
/// (the pan/tilt's axes meet at the beam).
pub(in crate::sequencer) fn config(settings: &Settings) -> StepperConfig {
    let mut geometry = settings.gimbal(crate::domain::AimModel::Exact).geometry;
    geometry.ol_cm = 0.0;
    let gimbal = Gimbal {
        model: GimbalModel::Exact,
        geometry,
    };
    StepperConfig::from_settings(&settings.stepper, gimbal)
}

/// Whether the stepper of `settings` reaches board point `p` within its
/// soft limits.
#[inline(never)]
pub(in crate::sequencer) fn reaches(settings: &Settings, p: PointCm) -> bool {
    let config = config(settings);
    config
        .gimbal
        .ik(BoardPoint::new(p.x_cm, p.y_cm))
        .is_ok_and(|j| config.steps_of(j).is_ok())
}

pub(in crate::sequencer) mod gcode;
pub(in crate::sequencer) mod points;

#[cfg(test)]
mod arc_tests;
#[cfg(test)]
mod tests;
