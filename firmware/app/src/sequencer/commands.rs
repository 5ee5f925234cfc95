//! Command handling: each command gets exactly one closing reply, and
//! changes state only when it is accepted.

use crate::command::Command;
use crate::domain::{AimModel, Pattern, PatternCheck, PatternError, Target, check_target};
use crate::galvo::GalvoError;
use crate::sequencer::drivers::{Drivers, NO_GALVO, galvo};
use crate::sequencer::machine::{
    Action, ActionSink, AfterCheck, CHECKS_PER_STEP, Core, Pending, Readings,
};
use crate::sequencer::run::{RunKind, Start};
use crate::settings::{JumpPlanner, PARAMS, ParamLine, ParamSpec};

impl Core {
    /// Runs `command` (`readings`: what the shell read from the links).
    pub(super) fn command(
        &mut self,
        command: Command,
        readings: &Readings,
        out: &mut dyn ActionSink,
    ) {
        if let Some(reason) = self.refusal_for_dead_servo(&command) {
            self.error(out, reason);
            return;
        }
        match command {
            Command::Help | Command::Version | Command::Status | Command::Get(_) => {
                self.report(command, readings, out);
                self.ok(out);
            }
            Command::Params => {
                for param in PARAMS {
                    self.param_line(param, out);
                }
                self.ok(out);
            }
            Command::Stop => {
                self.stop("stop command", out);
                self.ok(out);
            }
            Command::Arm => self.arm(out),
            // The shell switched the trace as the command arrived.
            Command::Trace(_) => self.ok(out),
            Command::Home => match self.session().start_homing(out) {
                Ok(()) => self.ok(out),
                Err(reason) => self.error(out, reason),
            },
            Command::Pattern { pattern, once } => self.check(
                pattern,
                AfterCheck::Start(Start::Pattern { pattern, once }),
                out,
            ),
            Command::Goto(point) => self.goto(Target { point, grid: None }, out),
            Command::Grid { xi, yi } => match self.aimer.grid_point(xi, yi) {
                Ok(target) => self.goto(target, out),
                Err(reason) => self.error(out, reason),
            },
            Command::Target(_) | Command::Planner(_) | Command::GalvoStatus => {
                self.galvo_command(command, readings, out)
            }
            Command::Laser(mode) => {
                self.settings.laser_mode = mode;
                galvo::points::allow_laser(self.run, &self.settings, &self.inputs, out);
                self.ok(out);
            }
            Command::Model(model) => self.set_model(model, out),
            Command::Set { param, value } => self.set(param, value, out),
            // A save may erase a flash sector (when one fills up), which
            // stalls the CPU for 1-2 s on the target: not while the laser
            // draws.
            Command::Save if self.run.is_some() => {
                self.error(out, "stop the running pattern or goto before save");
            }
            Command::Save => {
                self.pending = Some(Pending::Save);
                out.act(Action::Save);
            }
            Command::Grbl(line) => self.session().line(line.as_str(), out),
            Command::Servo(setup) => self.servo_setup(setup, out),
            Command::Preset(preset) => self.preset(preset, out),
        }
    }

    /// `target`, `planner` and `galvo status`: refused when no galvo loop
    /// serves the link (except `target gimbal`, and `target stepper`,
    /// refused when no stepper task serves its link).
    fn galvo_command(&mut self, command: Command, readings: &Readings, out: &mut dyn ActionSink) {
        let galvo_attached = self.inputs.galvo_room.is_some();
        let served = match command {
            Command::Target(actuator) => {
                Drivers::check_attached(actuator, galvo_attached, self.inputs.stepper_attached)
            }
            _ if galvo_attached => Ok(()),
            _ => Err(NO_GALVO),
        };
        if let Err(reason) = served {
            return self.error(out, reason);
        }
        match command {
            Command::Target(actuator) => {
                // The running pattern or goto stops: it was checked for
                // the old actuator.
                self.stop("actuator changed", out);
                self.actuator = actuator;
                self.configure_galvo(out);
            }
            Command::Planner(JumpPlanner::Seed) if !self.inputs.galvo_bisection => {
                return self.error(out, GalvoError::SeedTooSlow);
            }
            Command::Planner(planner) => {
                self.settings.galvo.planner = planner;
                self.configure_galvo(out);
            }
            _ => galvo::points::report_status(&self.settings, &readings.galvo, out),
        }
        self.ok(out);
    }

    /// `model`: re-aims the current point with the new model; on the
    /// galvo the new job replaces the one running (a dwell or a hold), it
    /// does not queue behind it.
    fn set_model(&mut self, model: AimModel, out: &mut dyn ActionSink) {
        self.model = model;
        self.geometry_changed();
        if self.run.is_some() {
            self.drivers_supersede(out);
            self.begin_point(out);
        }
        self.ok(out);
    }

    /// `set`: the running pattern (if any) must still be reachable with
    /// the new value; it continues with it from its next point (a path's
    /// shape and step from its next pass).
    fn set(&mut self, param: &'static ParamSpec, value: f64, out: &mut dyn ActionSink) {
        let before = self.settings;
        if let Err(e) = self.settings.set(param, value) {
            return self.error(out, e);
        }
        self.geometry_changed();
        match self.run.map(|r| r.kind) {
            Some(RunKind::Goto(target)) => {
                let checked = check_target(&self.aimer, self.actuator, &target);
                self.settings_checked(before, checked, out);
            }
            Some(kind) => match kind.pattern() {
                Some(pattern) => self.check(pattern, AfterCheck::KeepSettings { before }, out),
                None => self.settings_checked(before, Ok(()), out),
            },
            None => self.settings_checked(before, Ok(()), out),
        }
    }

    /// Ends a `set` whose check gave `checked`.
    fn settings_checked(
        &mut self,
        before: crate::settings::Settings,
        checked: Result<(), PatternError>,
        out: &mut dyn ActionSink,
    ) {
        match checked {
            Ok(()) => {
                let junction = self.settings.gcode_junction_mm;
                if before.galvo != self.settings.galvo || before.gcode_junction_mm != junction {
                    self.configure_galvo(out);
                }
                self.configure_stepper(out);
                self.ok(out);
            }
            Err(reason) => {
                self.settings = before;
                self.geometry_changed();
                self.error(out, reason);
            }
        }
    }

    /// Aims at one target and holds it; refuses unreachable targets.
    pub(super) fn goto(&mut self, target: Target, out: &mut dyn ActionSink) {
        match check_target(&self.aimer, self.actuator, &target) {
            Ok(()) => {
                self.start(Start::Goto(target), out);
                self.ok(out);
            }
            Err(e) => self.error(out, e),
        }
    }

    /// Checks that `pattern` is reachable at its probe points (see
    /// [`PatternCheck`]; the run checks every other point before
    /// it goes there), then does `then`. A few points per step: the shell
    /// lets the other tasks run in between.
    fn check(&mut self, pattern: Pattern, then: AfterCheck, out: &mut dyn ActionSink) {
        match PatternCheck::new(&pattern, &self.aimer, self.actuator) {
            Ok(check) => {
                self.pending = Some(Pending::Check { check, then });
                self.check_step(CHECKS_PER_STEP, out);
            }
            Err(e) => self.checked(then, Err(e), out),
        }
    }

    /// Checks up to `points` more points of the pending check (none
    /// pending: nothing); asks for the next step when more are left.
    pub(super) fn check_step(&mut self, points: usize, out: &mut dyn ActionSink) {
        if !matches!(self.pending, Some(Pending::Check { .. })) {
            return;
        }
        let Some(Pending::Check { mut check, then }) = self.pending.take() else {
            return;
        };
        match check.step(&self.aimer, self.actuator, points) {
            Ok(false) => {
                self.pending = Some(Pending::Check { check, then });
                out.act(Action::Yield);
            }
            Ok(true) => self.checked(then, Ok(()), out),
            Err(e) => self.checked(then, Err(e), out),
        }
    }

    /// Does what follows a check that gave `checked`.
    fn checked(
        &mut self,
        then: AfterCheck,
        checked: Result<(), PatternError>,
        out: &mut dyn ActionSink,
    ) {
        match (then, checked) {
            (AfterCheck::Start(start), Ok(())) => {
                self.start(start, out);
                self.ok(out);
            }
            (AfterCheck::Start(_), Err(reason)) => self.error(out, reason),
            (AfterCheck::KeepSettings { before }, checked) => {
                self.settings_checked(before, checked, out)
            }
        }
    }

    /// The store's answer to a save.
    pub(super) fn saved(&mut self, result: Result<(), &'static str>, out: &mut dyn ActionSink) {
        if !matches!(self.pending, Some(Pending::Save)) {
            return;
        }
        self.pending = None;
        match result {
            Ok(()) => self.ok(out),
            Err(reason) => self.error(out, reason),
        }
    }

    /// One `params` / `get` line.
    pub(super) fn param_line(&self, param: &ParamSpec, out: &mut dyn ActionSink) {
        self.data(
            out,
            format_args!("{}", ParamLine(param, self.settings.get(param))),
        );
    }
}
