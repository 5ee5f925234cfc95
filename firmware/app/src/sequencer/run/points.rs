//! Running a pattern or goto point by point on the drivers that draw.

use crate::domain::{AimModel, PathCursor, Pattern, Target};
use crate::galvo::GalvoEvent;
use crate::log;
use crate::sequencer::drivers::dispatch::aim;
use crate::sequencer::drivers::{Arrival, PathRun, Said, galvo, stepper};
use crate::sequencer::laser::LaserEvent;
use crate::sequencer::machine::{Action, ActionSink, Core, Line};
use crate::sequencer::run::{Run, RunKind, Start};
use crate::servo::task::ServoOutcome;
use crate::status::Phase;
use crate::stepper::StepperEvent;
use embassy_time::Duration;

impl Core {
    /// Starts `start` at its first point.
    pub(in crate::sequencer) fn start(&mut self, start: Start, out: &mut dyn ActionSink) {
        let (name, once) = match start {
            Start::Goto(_) => ("goto", true),
            Start::Pattern { pattern, once } => (pattern.name(), once),
        };
        log::info!("start {} (once={})", name, once);
        self.session().abort(out);
        out.act(Action::Note(LaserEvent::RunStarted));
        // Nothing of an earlier run may shine: a new gate generation, and
        // the galvo drops its points and an underrun latch; the stepper
        // comes to rest before the new run's first move.
        self.close_gate(out);
        stepper::points::stop(self.drivers(), out);
        self.run = None;
        match self.run_kind(start) {
            Some(kind) => {
                self.run = Some(Run::new(kind));
                self.begin_point(out);
            }
            None => {
                log::info!("stop {} (pattern has no points)", name);
                self.stop("pattern has no points", out);
            }
        }
    }

    /// How `start` runs on the current actuator; `None` when it has no
    /// points (a path that cannot be interpolated, or one the gimbal
    /// cannot draw).
    fn run_kind(&self, start: Start) -> Option<RunKind> {
        let (pattern, once) = match start {
            Start::Goto(target) => return Some(RunKind::Goto(target)),
            Start::Pattern { pattern, once } => (pattern, once),
        };
        if let Pattern::Grid(pattern) = pattern {
            return Some(RunKind::Grid { pattern, once });
        }
        // The stepper traces paths exactly; with `model seed` it keeps the
        // seed's point-by-point method (for comparison), as the gimbal.
        match self.drivers().path_run(self.model == AimModel::Exact) {
            PathRun::Traced => stepper::points::traced(pattern, once),
            PathRun::Marked => Some(RunKind::Marked { pattern, once }),
            PathRun::Refused => None,
            PathRun::Points => {
                let cursor = self.path_cursor(&pattern)?;
                Some(RunKind::Path {
                    pattern,
                    once,
                    cursor,
                })
            }
        }
    }

    /// The cursor at the first point of a pass of `pattern` (`None` when
    /// it cannot be interpolated).
    fn path_cursor(&self, pattern: &Pattern) -> Option<PathCursor> {
        PathCursor::start(pattern, &self.aimer)?.ok()
    }

    /// Stops whatever runs ([`Session::stop`](crate::sequencer::gcode::context::Session::stop)).
    pub(in crate::sequencer) fn stop(&mut self, why: &'static str, out: &mut dyn ActionSink) {
        self.session().stop(why, out);
    }

    /// The target of the current point of the run (`None`: past the last
    /// point, or a path the galvo marks whole).
    fn current_target(&self) -> Option<Target> {
        let run = self.run?;
        match run.kind {
            RunKind::Goto(target) => Some(target),
            RunKind::Grid { pattern, .. } => {
                self.aimer.grid_target(&Pattern::Grid(pattern), run.index)
            }
            RunKind::Path { cursor, .. } => Some(cursor.target()),
            RunKind::Traced { pattern, .. } => stepper::points::traced_target(&pattern, run.index),
            RunKind::Marked { .. } => None,
        }
    }

    /// Sends the current point to the actuator(s).
    pub(in crate::sequencer) fn begin_point(&mut self, out: &mut dyn ActionSink) {
        let Some(run) = self.run else { return };
        if let RunKind::Marked { pattern, .. } = run.kind {
            self.session()
                .with_stage(out, |st, _, out| galvo::points::mark(st, pattern, out));
            return;
        }
        let Some(target) = self.current_target() else {
            self.stop("pattern has no points", out);
            return;
        };
        // Travel to the first point of a pass (or to a goto target) is off
        // the figure: dark in every laser mode. A later pass of a closed
        // figure starts where the last one ended (arrived there): no travel.
        let holds = matches!(run.kind, RunKind::Goto(_));
        let closed = run.pass > 0 && self.last_aim.is_some_and(|(t, _)| t.point == target.point);
        let approach = holds || (run.index == 0 && !closed);
        let (mut moves, mut jobs) = (false, false);
        for driver in self.drivers().iter() {
            let mut session = self.session();
            if !session.with_stage(out, |st, _, out| aim(driver, st, target, approach, out)) {
                return;
            }
            match driver.arrival() {
                Arrival::Move => moves = true,
                Arrival::Job => jobs = true,
            }
        }
        if let Some(run) = self.run.as_mut() {
            run.phase = if approach {
                Phase::Approaching
            } else {
                Phase::Moving
            };
            run.dwell_until = None;
            run.gimbal_busy = moves;
            // A goto's galvo holds the point, laser on, until the next
            // command: nothing to wait for.
            run.galvo_busy = jobs && !holds;
        }
        self.point_finished_if_done(out);
    }

    /// The point of the running pattern is re-aimed (`model`): a driver
    /// whose jobs queue drops the one running first (a servo move
    /// supersedes the last by itself).
    pub(in crate::sequencer) fn drivers_supersede(&mut self, out: &mut dyn ActionSink) {
        if self.drivers().any(|d| d.arrival() == Arrival::Job) {
            crate::sequencer::drivers::stage::stop_galvo(&mut self.inputs, out);
        }
    }

    /// Does what a driver's report asks ([`Said`]).
    pub(in crate::sequencer) fn driver_said(&mut self, said: Said, out: &mut dyn ActionSink) {
        let notice = |out: &mut dyn ActionSink, text| out.act(Action::Line(Line::Notice(text)));
        match said {
            Said::Nothing => {}
            Said::Arrived(seq) => self.start_dwell(seq, out),
            Said::JobDone(seq) => {
                if let Some(run) = self.run.as_mut().filter(|r| r.galvo_seq == seq) {
                    run.galvo_busy = false;
                    self.point_finished_if_done(out);
                }
            }
            Said::Stop(text, why) => {
                text.into_iter().for_each(|text| notice(out, text));
                self.stop(why, out);
            }
            Said::Notice(text) => notice(out, text),
            Said::Homed(text, steps, failed) => {
                notice(out, text);
                self.session().homing_done(steps, failed, out);
            }
        }
    }

    /// A report of the galvo loop: the G-code session's first, else what
    /// it says of the run.
    pub(in crate::sequencer) fn galvo_event(
        &mut self,
        event: GalvoEvent,
        out: &mut dyn ActionSink,
    ) {
        if !self.session().galvo_event(&event, out) {
            let idle = self.gcode.motion.is_idle();
            self.driver_said(galvo::points::said(event, self.run, idle), out);
        }
    }

    /// A report of the stepper task: the G-code session's first, else
    /// what it says of the run.
    pub(in crate::sequencer) fn stepper_event(
        &mut self,
        event: StepperEvent,
        out: &mut dyn ActionSink,
    ) {
        if self.session().stepper_event(&event, out) {
            return;
        }
        // The run's current point, for messages.
        let target = (self.last_aim).map_or((0.0, 0.0), |(t, _)| (t.point.x_cm, t.point.y_cm));
        let said = stepper::points::said(event, &self.settings, self.run, target);
        self.driver_said(said, out);
    }

    /// The servo task's report.
    pub(in crate::sequencer) fn servo_outcome(
        &mut self,
        outcome: ServoOutcome,
        out: &mut dyn ActionSink,
    ) {
        let gcode_fault = self.session().servo_outcome(&outcome, out);
        match outcome {
            ServoOutcome::Recovered { id } => self.servo_recovered(id, out),
            ServoOutcome::Arrived {
                seq,
                yaw_tenths,
                pitch_tenths,
            } => self.arrived(seq, (yaw_tenths, pitch_tenths), out),
            ServoOutcome::Fault { seq, id, fault } => self.servo_fault(seq, id, fault, out),
            ServoOutcome::Superseded { .. } => {}
            ServoOutcome::Bus { seq, report } => self.servo_bus_report(seq, report, out),
        }
        if gcode_fault {
            self.stop("servo fault during G-code", out);
        }
    }

    /// Both servos arrived at move `seq`, measured at `tenths` (yaw,
    /// pitch; 0.1°): the dwell starts when it is the current move.
    fn arrived(&mut self, seq: u32, tenths: (i16, i16), out: &mut dyn ActionSink) {
        self.measured = Some(tenths);
        // Both servos answered and arrived: they are alive.
        self.faults
            .arrived(self.settings.yaw.id, self.settings.pitch.id);
        self.start_dwell(seq, out);
        log::info!("arrived (servo {} {})", tenths.0, tenths.1);
    }

    /// The pointing actuator (gimbal or stepper) arrived at move `seq`:
    /// the dwell starts when it is the current move.
    pub(in crate::sequencer) fn start_dwell(&mut self, seq: u32, out: &mut dyn ActionSink) {
        let now = self.inputs.now;
        let dwell_ms = self.settings.dwell_ms;
        let Some(run) = self.run.as_mut().filter(|r| r.seq == seq) else {
            return;
        };
        run.phase = Phase::Dwelling;
        out.act(Action::Note(LaserEvent::GimbalArrived));
        let dwell = if run.kind.pattern().is_some_and(|p| p.is_path()) {
            0.0
        } else {
            dwell_ms
        };
        run.dwell_until = Some(now.saturating_add(Duration::from_micros((dwell * 1000.0) as u64)));
    }

    /// The dwell on the current point ended: next point, next pass, or done.
    pub(in crate::sequencer) fn dwell_finished(&mut self, out: &mut dyn ActionSink) {
        if let Some(run) = self.run.as_mut() {
            run.dwell_until = None;
            run.gimbal_busy = false;
        }
        self.point_finished_if_done(out);
    }

    /// When every actuator is done with the current point: the next
    /// point, the next pass, the end — or, for a goto, holding.
    pub(in crate::sequencer) fn point_finished_if_done(&mut self, out: &mut dyn ActionSink) {
        let Some(mut run) = self.run else { return };
        if run.gimbal_busy || run.galvo_busy {
            return;
        }
        run.index += 1;
        let more = match &mut run.kind {
            RunKind::Goto(_) => {
                // A goto holds its point until the next command.
                if let Some(run) = self.run.as_mut() {
                    run.phase = Phase::Holding;
                }
                return;
            }
            RunKind::Grid { pattern, .. } => self
                .aimer
                .grid_target(&Pattern::Grid(*pattern), run.index)
                .is_some(),
            RunKind::Path { cursor, .. } => cursor.advance(),
            RunKind::Traced { pattern, .. } => {
                stepper::points::traced_target(pattern, run.index).is_some()
            }
            RunKind::Marked { .. } => false,
        };
        if !more {
            run.pass += 1;
            run.index = 0;
            if run.kind.once() {
                self.run = Some(run);
                self.stop("pattern complete", out);
                return;
            }
            // A new pass takes the path parameters as they are now.
            if let RunKind::Path {
                pattern, cursor, ..
            } = &mut run.kind
            {
                let Some(start) = self.path_cursor(pattern) else {
                    self.run = Some(run);
                    self.stop("pattern has no points", out);
                    return;
                };
                *cursor = start;
            }
        }
        self.run = Some(run);
        self.begin_point(out);
    }
}
