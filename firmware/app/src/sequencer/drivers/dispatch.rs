//! The driver-specific arm of the calls that go to each driver that
//! draws: a pattern's point ([`aim`]) and a G-code step ([`step`]), each
//! in the driver's own module, chosen here.

use crate::domain::Target;
use crate::sequencer::drivers::stage::Stage;
use crate::sequencer::drivers::{Driver, DriverJobs, DriverStep, galvo, gimbal, stepper};
use crate::sequencer::io::ActionSink;

/// Aims `driver` at a pattern's current point `target` (`approach`:
/// travel to it, dark); `false` when it could not (it asked the stage
/// for a stop).
pub(in crate::sequencer) fn aim(
    driver: Driver,
    st: &mut Stage,
    target: Target,
    approach: bool,
    out: &mut dyn ActionSink,
) -> bool {
    match driver {
        Driver::Gimbal => gimbal::points::aim(st, target, out),
        Driver::Stepper => stepper::points::aim(st, target, approach, out),
        Driver::Galvo => galvo::points::aim(st, target, out),
    }
}

/// Sends G-code step `step` to `driver`; its request number, `None` when
/// it could not be sent (it asked the stage for a stop) or when the
/// driver takes blocks whole instead (the stepper: `StepperJob::send`).
pub(in crate::sequencer) fn step(
    driver: Driver,
    st: &mut Stage,
    jobs: &mut DriverJobs,
    step: DriverStep,
    out: &mut dyn ActionSink,
) -> Option<u32> {
    match driver {
        Driver::Gimbal => {
            gimbal::step::send_step(st, step.from, step.to, step.feed, step.corner, out)
        }
        Driver::Galvo => (jobs.galvo).send_step(st, step.from, step.to, step.feed, step.lit, out),
        Driver::Stepper => None,
    }
}
