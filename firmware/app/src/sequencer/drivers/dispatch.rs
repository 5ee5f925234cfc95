//! The driver interface's dispatch: each question to the driver(s) that draw.

use crate::domain::{PointCm, Target};
use crate::grbl::Block;
use crate::sequencer::drivers::{Arrival, Driver, DriverStep, Drivers, gimbal, stepper};
use crate::sequencer::gcode::queue::planned_length;
use crate::sequencer::machine::{ActionSink, Core};

impl Core {
    /// The driver(s) that draw.
    pub(in crate::sequencer) fn drivers(&self) -> Drivers {
        Drivers::of(self.actuator)
    }

    /// Whether `driver` reaches board point `p` (cm).
    pub(in crate::sequencer) fn driver_reaches(&self, driver: Driver, p: PointCm) -> bool {
        match driver {
            Driver::Gimbal => self.aimer.aim(p).is_ok(),
            Driver::Galvo => self.aimer.galvo_in_range(p),
            Driver::Stepper => stepper::gcode::reaches(&self.settings, p),
        }
    }

    /// Whether every driver that draws reaches board point `p` (cm).
    pub(in crate::sequencer) fn drivers_reach(&self, p: PointCm) -> bool {
        self.drivers().iter().all(|d| self.driver_reaches(d, p))
    }

    /// Aims `driver` at a pattern's current point `target` (`approach`:
    /// travel, dark); `false` when it could not (the run stopped).
    pub(in crate::sequencer) fn driver_aim(
        &mut self,
        driver: Driver,
        target: Target,
        approach: bool,
        out: &mut dyn ActionSink,
    ) -> bool {
        match driver {
            Driver::Gimbal => self.begin_gimbal_move(target, out),
            Driver::Stepper => self.begin_stepper_move(target, approach, out),
            Driver::Galvo => self.begin_galvo_point(target, out),
        }
    }

    /// The point of the running pattern is re-aimed (`model`): a driver
    /// whose jobs queue drops the one running first (a servo move
    /// supersedes the last by itself).
    pub(in crate::sequencer) fn drivers_supersede(&mut self, out: &mut dyn ActionSink) {
        if self.drivers().any(|d| d.arrival() == Arrival::Job) {
            self.stop_galvo(out);
        }
    }

    /// grbl's soft reset: a driver that can drop its motion at once does
    /// (the stepper's steps are killed; the position is then uncertain);
    /// the stop that follows brakes the others.
    pub(in crate::sequencer) fn drivers_reset(&mut self, out: &mut dyn ActionSink) {
        if self.drivers().hands_over_blocks() {
            out.act(crate::sequencer::io::Action::Stepper(
                crate::stepper::StepperRequest::Halt,
            ));
        }
    }

    /// Offers `block`, just taken from the motion queue, to a driver that
    /// plans whole blocks itself (the gimbal alone streams them through
    /// its look-ahead plan); `true` when it took it (it is then the
    /// current block).
    pub(in crate::sequencer) fn drivers_take_block(
        &mut self,
        block: &Block,
        out: &mut dyn ActionSink,
    ) -> bool {
        if !(self.drivers().gimbal_streams() && planned_length(block).is_some()) {
            return false;
        }
        self.gcode.motion.current = Some(self.new_current(*block, 1));
        self.stream_begin(block, out)
    }

    /// Hands the current G-code step to a driver with a stage of its own
    /// (the gimbal following its planned profile, the stepper taking
    /// blocks whole); `false` when the drivers take it step by step
    /// ([`Core::driver_step`]).
    pub(in crate::sequencer) fn drivers_send_in_own_stage(
        &mut self,
        out: &mut dyn ActionSink,
    ) -> bool {
        if self.jobs.gimbal.is_following() {
            self.stream_tick(out);
        } else if self.drivers().hands_over_blocks() {
            self.gcode_stepper_send(out);
        } else {
            return false;
        }
        true
    }

    /// Sends the G-code step from `from` to `to` (`feed` mm/min, `None`:
    /// rapid; `lit`; `corner`: it ends a block) to `driver`; its request
    /// number, `None` when it could not be sent (the session stopped).
    pub(in crate::sequencer) fn driver_step(
        &mut self,
        driver: Driver,
        step: DriverStep,
        out: &mut dyn ActionSink,
    ) -> Option<u32> {
        match driver {
            Driver::Gimbal => self.with_stage(out, |st, _, out| {
                gimbal::step::send_step(st, step.from, step.to, step.feed, step.corner, out)
            }),
            Driver::Galvo => self.with_stage(out, |st, jobs, out| {
                (jobs.galvo).send_step(st, step.from, step.to, step.feed, step.lit, out)
            }),
            // Blocks are handed over whole (`gcode_stepper_send`).
            Driver::Stepper => None,
        }
    }
}
