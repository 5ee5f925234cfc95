//! The session's side of the drivers: a driver's G-code stage (a method
//! of its own state in [`DriverJobs`](crate::sequencer::drivers::DriverJobs))
//! is called with a [`Stage`](crate::sequencer::drivers::stage::Stage)
//! ([`Session::with_stage`]), and what follows it is here: a line waiting
//! for room answered, the step finished, a hold held or resumed. The
//! drivers' reports come here first: what is not the session's goes on to
//! the core (as a [`Said`](crate::sequencer::drivers::Said)).

use crate::galvo::{GalvoEvent, MarkStop};
use crate::grbl::Block;
use crate::sequencer::drivers::{Driver, DriverStep, dispatch};
use crate::sequencer::gcode::context::Session;
use crate::sequencer::gcode::queue::{CORNER_SETTLE_MS, Hold, planned_length, point_at};
use crate::sequencer::gcode::report;
use crate::sequencer::io::{Action, ActionSink};
use crate::sequencer::laser::LaserEvent;
use crate::servo::task::ServoOutcome;
use crate::stepper::StepperRequest;
use embassy_time::Duration;

impl Session<'_> {
    /// grbl's soft reset: a driver that can drop its motion at once does
    /// (the stepper's steps are killed; the position is then uncertain);
    /// the stop that follows brakes the others.
    pub(in crate::sequencer) fn drivers_reset(&mut self, out: &mut dyn ActionSink) {
        if self.drivers().hands_over_blocks() {
            out.act(Action::Stepper(StepperRequest::Halt));
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
        self.gcode.motion.current = Some(self.gcode.new_current(*block, 1));
        self.stream_begin(block, out)
    }

    /// Hands the current G-code step to a driver with a stage of its own
    /// (the gimbal following its planned profile, the stepper taking
    /// blocks whole); `false` when the drivers take it step by step
    /// ([`Session::driver_step`]).
    pub(in crate::sequencer) fn drivers_send_in_own_stage(
        &mut self,
        out: &mut dyn ActionSink,
    ) -> bool {
        if self.jobs.gimbal.is_following() {
            self.stream_tick(out);
        } else if self.drivers().hands_over_blocks() {
            self.stepper_send(out);
        } else {
            return false;
        }
        true
    }

    /// Sends the G-code step `step` to `driver` ([`dispatch::step`]);
    /// its request number, `None` when it could not be sent (the session
    /// stopped).
    pub(in crate::sequencer) fn driver_step(
        &mut self,
        driver: Driver,
        step: DriverStep,
        out: &mut dyn ActionSink,
    ) -> Option<u32> {
        self.with_stage(out, |st, jobs, out| {
            dispatch::step(driver, st, jobs, step, out)
        })
    }

    /// A report of the galvo loop, when it is the G-code session's (its
    /// step done, refused, its hold's stop): `true` when it was.
    pub(in crate::sequencer) fn galvo_event(
        &mut self,
        event: &GalvoEvent,
        out: &mut dyn ActionSink,
    ) -> bool {
        match *event {
            GalvoEvent::Done { seq } => self.galvo_done(seq, out),
            GalvoEvent::Refused { seq, error } if self.awaits_galvo(seq) => {
                report::notice(out, format_args!("MSG:galvo: {error}"));
                self.alarm(crate::grbl::Alarm::SoftLimit, out);
                true
            }
            GalvoEvent::Stopped(at) => {
                self.galvo_stopped(at, out);
                true
            }
            _ => false,
        }
    }

    /// Sends the pieces that continue the galvo stroke in flight.
    pub(in crate::sequencer) fn galvo_send_ahead(&mut self, out: &mut dyn ActionSink) {
        self.with_stage(out, |st, jobs, out| jobs.galvo.send_ahead(st, out));
    }

    /// The galvo loop finished job `seq`; `true` when it was the G-code
    /// step's.
    pub(in crate::sequencer) fn galvo_done(&mut self, seq: u32, out: &mut dyn ActionSink) -> bool {
        let Some(c) = self.gcode.motion.current.as_mut() else {
            return false;
        };
        if c.galvo_seq != Some(seq) {
            return false;
        }
        c.galvo_seq = None;
        if self.with_stage(out, |st, jobs, _| jobs.galvo.done(st, seq)) {
            self.gcode.take_owed(out);
        }
        self.step_done(out);
        self.with_stage(out, |st, jobs, out| jobs.galvo.drop_unadopted(st, out));
        true
    }

    /// Whether the G-code step waits for galvo job `seq`.
    pub(in crate::sequencer) fn awaits_galvo(&self, seq: u32) -> bool {
        self.gcode
            .motion
            .current
            .is_some_and(|c| c.galvo_seq == Some(seq))
            || self.jobs.galvo.ahead_is(seq)
    }

    /// The galvo stopped (`at`: where marking ended, if it marked): when a
    /// hold waits for it, what was marked is done and the hold is held
    /// (or, resumed meanwhile, goes on from the stop point).
    #[inline(never)]
    pub(in crate::sequencer) fn galvo_stopped(
        &mut self,
        at: Option<MarkStop>,
        out: &mut dyn ActionSink,
    ) {
        let Some(moved) = self.with_stage(out, |st, jobs, _| jobs.galvo.stopped(st, at)) else {
            return;
        };
        if moved {
            // The blocks left the queue: a line waiting for room is queued.
            self.gcode.take_owed(out);
        }
        // Held; `~` came while stopping: resumed at once.
        let motion = &mut self.gcode.motion;
        let resumed = motion.hold == Hold::None;
        motion.hold = Hold::Held;
        if resumed {
            self.resume(out);
        }
    }

    /// Starts the gimbal following `block` (the block in flight);
    /// `false` when it has nothing to move (it then runs step by step).
    pub(in crate::sequencer) fn stream_begin(
        &mut self,
        block: &Block,
        out: &mut dyn ActionSink,
    ) -> bool {
        let begun = self.with_stage(out, |st, jobs, out| jobs.gimbal.begin(st, block, out));
        if begun == Some(true) {
            self.stream_rest(out);
        }
        begun.is_some()
    }

    /// One period of the block the gimbal follows.
    pub(in crate::sequencer) fn stream_tick(&mut self, out: &mut dyn ActionSink) {
        if self.with_stage(out, |st, jobs, out| jobs.gimbal.tick(st, out)) {
            self.stream_rest(out);
        }
    }

    /// The tick reached the end of a block that joins the next at speed:
    /// the next block (queued, planned) goes on from here, hold or not.
    #[inline(never)]
    pub(in crate::sequencer) fn stream_block_done(&mut self, out: &mut dyn ActionSink) {
        let motion = &mut self.gcode.motion;
        let mut cancelled = false;
        if let Some(c) = motion.current.take() {
            motion.position = point_at(&c.block, 1, 1);
            cancelled = c.cancelled;
        }
        let next = motion.queue.front().copied();
        match next.filter(|b| planned_length(b).is_some()) {
            Some(block) => {
                motion.queue.pop_front();
                self.gcode.take_owed(out);
                self.gcode.motion.current = Some(self.gcode.new_current(block, 1));
                if !self.stream_begin(&block, out) {
                    self.gcode.motion.current = None;
                    self.advance(out);
                }
            }
            None => {
                self.jobs.gimbal.clear();
                if cancelled {
                    // A jog cancel between this block's end and the next:
                    // the parser had gone on to the dropped jogs' ends.
                    self.gcode.sync_position();
                }
                self.advance(out);
            }
        }
    }

    /// A hold came to rest (`~` goes on from here), or a jog cancel did
    /// (the jog ends here).
    #[inline(never)]
    fn stream_rest(&mut self, out: &mut dyn ActionSink) {
        let motion = &mut self.gcode.motion;
        motion.gimbal_lit = false;
        let cancelled = motion.current.is_some_and(|c| c.cancelled);
        if let Some(c) = motion.current.as_mut() {
            // The sample's arrival is not waited for.
            c.servo_seq = None;
            c.until = None;
        }
        if cancelled {
            motion.current = None;
            self.jobs.gimbal.clear();
            self.gcode.sync_position();
            self.advance(out);
            return;
        }
        motion.hold = Hold::Held;
    }

    /// The servo task confirmed streamed move `seq`: `true` when it was
    /// a point on the way (the block goes on at its own pace).
    #[inline(never)]
    fn stream_arrived(&mut self, seq: u32) -> bool {
        let motion = &mut self.gcode.motion;
        let on_the_way = self.jobs.gimbal.is_following()
            && motion.current.is_some_and(|c| c.servo_seq == Some(seq));
        if on_the_way {
            motion.arrived = true;
            if let Some(c) = motion.current.as_mut() {
                c.servo_seq = None;
            }
        }
        on_the_way
    }

    /// The servo task reports move `seq` arrived; `true` when it was the
    /// G-code step's.
    fn servo_arrived(&mut self, seq: u32, out: &mut dyn ActionSink) -> bool {
        if self.stream_arrived(seq) {
            out.act(Action::Note(LaserEvent::GimbalArrived));
            return true;
        }
        let Some(c) = self.gcode.motion.current.as_mut() else {
            return false;
        };
        if c.servo_seq != Some(seq) {
            return false;
        }
        c.servo_seq = None;
        if c.index >= c.count && c.count > 0 {
            c.until = Some(
                self.inputs
                    .now
                    .saturating_add(Duration::from_millis(CORNER_SETTLE_MS)),
            );
        }
        self.gcode.motion.arrived = true;
        out.act(Action::Note(LaserEvent::GimbalArrived));
        self.step_done(out);
        true
    }

    /// The G-code side of a servo report: an arrival of the step in flight
    /// moves on; `true` for a fault of it (the caller stops, after its own
    /// fault handling).
    pub(in crate::sequencer) fn servo_outcome(
        &mut self,
        outcome: &ServoOutcome,
        out: &mut dyn ActionSink,
    ) -> bool {
        match *outcome {
            ServoOutcome::Arrived { seq, .. } => {
                self.servo_arrived(seq, out);
                false
            }
            ServoOutcome::Fault { seq, .. } => self.awaits_servo(seq),
            _ => false,
        }
    }

    /// Whether the G-code step waits for servo move `seq`.
    fn awaits_servo(&self, seq: u32) -> bool {
        self.gcode
            .motion
            .current
            .is_some_and(|c| c.servo_seq == Some(seq))
    }
}
