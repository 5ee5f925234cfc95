//! The session's and the core's side of the drivers: a driver is called
//! with a [`Stage`] of the core's state ([`Core::with_stage`]; its G-code
//! stage a method of its own state in [`DriverJobs`]), and what follows
//! it here is the session's (a line waiting for room answered, the step
//! finished, a hold held or resumed) or the core's (what it noted: a
//! stop, an alarm). The drivers' reports come here too: the session's
//! part first, the rest to the core as a [`Said`].

use crate::domain::PointCm;
use crate::galvo::{GalvoEvent, MarkStop};
use crate::grbl::Block;
use crate::sequencer::drivers::stage::Stage;
use crate::sequencer::drivers::{Driver, DriverJobs, DriverStep, Said, galvo, gimbal, stepper};
use crate::sequencer::gcode::queue::{CORNER_SETTLE_MS, Hold, planned_length, point_at};
use crate::sequencer::laser::LaserEvent;
use crate::sequencer::machine::{Action, ActionSink, Core};
use crate::servo::task::ServoOutcome;
use crate::stepper::{StepperEvent, StepperRequest};
use embassy_time::Duration;

impl Core {
    /// Runs `stage` on the drivers' state with a [`Stage`] of the core's;
    /// then the core does what it noted ([`Stage::then`]: everything stops
    /// when a galvo job found no room, …), and an alarm it raised is
    /// raised.
    pub(in crate::sequencer) fn with_stage<R>(
        &mut self,
        out: &mut dyn ActionSink,
        stage: impl FnOnce(&mut Stage, &mut DriverJobs, &mut dyn ActionSink) -> R,
    ) -> R {
        let drivers = self.drivers();
        let mut st = Stage {
            gcode: &mut self.gcode,
            settings: &self.settings,
            aimer: &self.aimer,
            inputs: &mut self.inputs,
            next_seq: &mut self.next_seq,
            run: &mut self.run,
            last_aim: &mut self.last_aim,
            measured: self.measured,
            drivers,
            alarm: None,
            then: Said::Nothing,
        };
        let result = stage(&mut st, &mut self.jobs, out);
        let (alarm, then) = (st.alarm, st.then);
        self.driver_said(then, out);
        if let Some(alarm) = alarm {
            self.grbl_alarm(alarm, out);
        }
        result
    }

    /// Whether every driver that draws reaches board point `p` (cm).
    pub(in crate::sequencer) fn drivers_reach(&self, p: PointCm) -> bool {
        self.drivers().reach(&self.aimer, &self.settings, p)
    }

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

    /// A report of the galvo loop: the G-code session's when it is (its
    /// step done, refused, its hold's stop); else what the galvo says of
    /// it, done by the core.
    pub(in crate::sequencer) fn galvo_event(
        &mut self,
        event: GalvoEvent,
        out: &mut dyn ActionSink,
    ) {
        match event {
            GalvoEvent::Done { seq } if self.gcode_galvo_done(seq, out) => {}
            GalvoEvent::Refused { seq, error } if self.gcode_awaits_galvo(seq) => {
                self.notify(out, format_args!("MSG:galvo: {error}"));
                self.grbl_alarm(crate::grbl::Alarm::SoftLimit, out);
            }
            GalvoEvent::Stopped(at) => self.gcode_galvo_stopped(at, out),
            _ => {
                let idle = self.gcode.motion.is_idle();
                self.driver_said(galvo::points::said(event, self.run, idle), out);
            }
        }
    }

    /// A report of the stepper task: the G-code session's when it is;
    /// else what the stepper says of it, done by the core.
    pub(in crate::sequencer) fn stepper_event(
        &mut self,
        event: StepperEvent,
        out: &mut dyn ActionSink,
    ) {
        if let StepperEvent::Homed { .. } | StepperEvent::HomingFailed { .. } = event {
            self.stepper_homing = false;
        }
        if self.gcode_stepper_event(&event, out) {
            return;
        }
        // The run's current point, for messages.
        let target = (self.last_aim).map_or((0.0, 0.0), |(t, _)| (t.point.x_cm, t.point.y_cm));
        let said = stepper::points::said(event, &self.settings, self.run, target);
        self.driver_said(said, out);
    }

    /// Sends the pieces that continue the galvo stroke in flight.
    pub(in crate::sequencer) fn gcode_galvo_send_ahead(&mut self, out: &mut dyn ActionSink) {
        self.with_stage(out, |st, jobs, out| jobs.galvo.send_ahead(st, out));
    }

    /// The galvo loop finished job `seq`; `true` when it was the G-code
    /// step's.
    pub(in crate::sequencer) fn gcode_galvo_done(
        &mut self,
        seq: u32,
        out: &mut dyn ActionSink,
    ) -> bool {
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
        self.gcode_step_done(out);
        self.with_stage(out, |st, jobs, out| jobs.galvo.drop_unadopted(st, out));
        true
    }

    /// Whether the G-code step waits for galvo job `seq`.
    pub(in crate::sequencer) fn gcode_awaits_galvo(&self, seq: u32) -> bool {
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
    pub(in crate::sequencer) fn gcode_galvo_stopped(
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
            self.grbl_resume(out);
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
                    self.grbl_advance(out);
                }
            }
            None => {
                self.jobs.gimbal.clear();
                if cancelled {
                    // A jog cancel between this block's end and the next:
                    // the parser had gone on to the dropped jogs' ends.
                    self.gcode.sync_position();
                }
                self.grbl_advance(out);
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
            self.grbl_advance(out);
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
    fn gcode_servo_arrived(&mut self, seq: u32, out: &mut dyn ActionSink) -> bool {
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
        self.gcode_step_done(out);
        true
    }

    /// The G-code side of a servo report: an arrival of the step in flight
    /// moves on; `true` for a fault of it (the caller stops, after its own
    /// fault handling).
    pub(in crate::sequencer) fn gcode_servo_outcome(
        &mut self,
        outcome: &ServoOutcome,
        out: &mut dyn ActionSink,
    ) -> bool {
        match *outcome {
            ServoOutcome::Arrived { seq, .. } => {
                self.gcode_servo_arrived(seq, out);
                false
            }
            ServoOutcome::Fault { seq, .. } => self.gcode_awaits_servo(seq),
            _ => false,
        }
    }

    /// Whether the G-code step waits for servo move `seq`.
    fn gcode_awaits_servo(&self, seq: u32) -> bool {
        self.gcode
            .motion
            .current
            .is_some_and(|c| c.servo_seq == Some(seq))
    }
}
