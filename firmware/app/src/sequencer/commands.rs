//! Command handling: each command gets its reply here, and changes state
//! only when it is accepted.

use super::targets::{self, PatternError, Target};
use super::{LaserSwitch, Phase, Run, Sequencer, SettingsStore};
use crate::build_info;
use crate::cli::parse::HELP_LINES;
use crate::command::{Actuator, ReplyText, reply_text};
use crate::command::{AimModel, Command, Pattern, PointCm};
use crate::galvo::GALVO_OUTPUT;
use crate::settings::{PARAMS, ParamLine};
use crate::status::{Activity, Snapshot};
use crate::text::Fixed;

impl<L: LaserSwitch, S: SettingsStore> Sequencer<'_, L, S> {
    /// Runs one command and sends its reply.
    pub(super) async fn handle_command(&mut self, command: Command) {
        let link = self.link;
        if let Some(reason) = self.refusal_for_dead_servo(&command) {
            link.error(reason);
            return;
        }
        match command {
            Command::Help => {
                for line in HELP_LINES {
                    link.data(format_args!("{line}"));
                }
                link.ok();
            }
            Command::Version => {
                link.data(format_args!(
                    "{} {} (git {}, {} build for {})",
                    build_info::PRODUCT,
                    build_info::VERSION,
                    build_info::GIT_REV,
                    build_info::PROFILE,
                    build_info::TARGET
                ));
                link.ok();
            }
            Command::Status => {
                self.report_status();
                link.ok();
            }
            Command::Stop => {
                self.stop("stop command");
                link.ok();
            }
            Command::Pattern { pattern, once } => match self.check_pattern(&pattern).await {
                Ok(()) => {
                    self.start(Run::new(Some(pattern), None, once));
                    link.ok();
                }
                Err(reason) => link.error(reason),
            },
            Command::Goto(point) => self.goto(Target { point, grid: None }),
            Command::Grid { xi, yi } => match targets::grid_point(&self.settings, xi, yi) {
                Ok(target) => self.goto(target),
                Err(reason) => link.error(reason),
            },
            Command::Target(actuator)
                if actuator != Actuator::Gimbal && !(GALVO_OUTPUT && self.galvo.is_some()) =>
            {
                link.error("this build has no galvo output")
            }
            Command::Target(actuator) => {
                // The running pattern or goto stops: it was checked for
                // the old actuator.
                self.stop("actuator changed");
                self.actuator = actuator;
                self.configure_galvo();
                link.ok();
            }
            Command::Planner(_) | Command::GalvoStatus if !GALVO_OUTPUT => {
                link.error("this build has no galvo output")
            }
            Command::Planner(planner) => {
                self.settings.galvo.planner = planner;
                self.configure_galvo();
                link.ok();
            }
            Command::GalvoStatus => {
                self.report_galvo_status();
                link.ok();
            }
            Command::Laser(mode) => {
                self.settings.laser_mode = mode;
                self.allow_galvo_laser();
                link.ok();
            }
            Command::Model(model) => {
                self.model = model;
                // Re-aim the current point with the new model; on the
                // galvo the new job replaces the one running (a dwell or
                // a hold), it does not queue behind it.
                if self.run.is_some() {
                    if self.actuator.uses_galvo() {
                        self.stop_galvo();
                    }
                    self.begin_point();
                }
                link.ok();
            }
            Command::Set { param, value } => {
                let before = self.settings;
                match self.settings.set(param, value) {
                    Ok(()) => match self.check_current_run().await {
                        Ok(()) => {
                            if GALVO_OUTPUT && before.galvo != self.settings.galvo {
                                self.configure_galvo();
                            }
                            link.ok()
                        }
                        Err(reason) => {
                            self.settings = before;
                            link.error(reason);
                        }
                    },
                    Err(e) => link.error(e),
                }
            }
            Command::Get(param) => {
                link.data(format_args!(
                    "{}",
                    ParamLine(param, self.settings.get(param))
                ));
                link.ok();
            }
            Command::Params => {
                for param in PARAMS {
                    link.data(format_args!(
                        "{}",
                        ParamLine(param, self.settings.get(param))
                    ));
                }
                link.ok();
            }
            // A save may erase a flash sector (when one fills up), which
            // stalls the CPU for 1-2 s on the target: not while the laser
            // draws.
            Command::Save if self.run.is_some() => {
                link.error("stop the running pattern or goto before save");
            }
            Command::Save => {
                let record = self.settings.to_record();
                match self.store.save(&record).await {
                    Ok(()) => link.ok(),
                    Err(reason) => link.error(reason),
                }
            }
        }
    }

    /// Aims at one target and holds it; refuses unreachable targets.
    fn goto(&mut self, target: Target) {
        match targets::check_target(&self.settings, self.model, self.actuator, &target) {
            Ok(_) => {
                self.start(Run::new(None, Some(target), true));
                self.link.ok();
            }
            Err(e) => self.link.error(e),
        }
    }

    /// `pattern` must be reachable at its probe points before it starts
    /// (see [`targets::PatternCheck`]; the run checks every other point
    /// before it goes there). A few points per executor step: the other
    /// tasks run in between.
    async fn check_pattern(&self, pattern: &Pattern) -> Result<(), PatternError> {
        let mut check = targets::PatternCheck::new(pattern, &self.settings, self.actuator)?;
        while !check.step(&self.settings, self.model, self.actuator, CHECKS_PER_STEP)? {
            embassy_futures::yield_now().await;
        }
        Ok(())
    }

    /// After a parameter change, the running pattern (if any) must still be
    /// reachable; it continues with the new values from its next point
    /// (a path's shape and step from its next pass).
    async fn check_current_run(&self) -> Result<(), PatternError> {
        match self.run {
            Some(Run {
                pattern: Some(pattern),
                ..
            }) => self.check_pattern(&pattern).await,
            Some(Run {
                single: Some(target),
                ..
            }) => targets::check_target(&self.settings, self.model, self.actuator, &target),
            _ => Ok(()),
        }
    }

    fn report_status(&self) {
        let snapshot = self.status.snapshot();
        for line in 0..STATUS_LINES {
            if let Some(text) = self.status_line(&snapshot, line) {
                self.link.data_line(text);
            }
        }
    }

    /// Line `line` of `status` (`None`: not shown now). One formatter and
    /// one queueing call in the caller keep the code small.
    fn status_line(&self, s: &Snapshot, line: usize) -> Option<ReplyText> {
        let text = |args: core::fmt::Arguments<'_>| Some(reply_text(args));
        match line {
            0 => {
                let uptime_ms = self.booted_at.elapsed().as_millis();
                text(format_args!(
                    "uptime: {}.{:03} s",
                    uptime_ms / 1000,
                    uptime_ms % 1000
                ))
            }
            1 => text(format_args!(
                "build: {} {} git {} {}",
                build_info::PRODUCT,
                build_info::VERSION,
                build_info::GIT_REV,
                build_info::PROFILE
            )),
            2 => match s.activity {
                Activity::Idle => text(format_args!("state: idle")),
                Activity::Goto => text(format_args!("state: goto")),
                Activity::Pattern(p) => text(format_args!(
                    "state: pattern {}{} point {} pass {}",
                    p.name(),
                    if self.run.is_some_and(|r| r.once) {
                        " once"
                    } else {
                        ""
                    },
                    s.point_index.unwrap_or(0),
                    s.pass
                )),
            },
            3 => text(format_args!(
                "phase: {}",
                match s.phase {
                    None => "-",
                    Some(Phase::Approaching) => "approaching",
                    Some(Phase::Moving) => "moving",
                    Some(Phase::Dwelling) => "dwelling",
                    Some(Phase::Holding) => "holding",
                }
            )),
            4 => text(format_args!("actuator: {}", self.actuator.name())),
            5 => text(format_args!(
                "model: {}",
                match self.model {
                    AimModel::Exact => "exact",
                    AimModel::Seed => "seed",
                }
            )),
            6 => {
                let (target, _) = s.target?;
                let PointCm { x_cm, y_cm } = target.point;
                let (x_cm, y_cm) = (Fixed::<3>(x_cm), Fixed::<3>(y_cm));
                match target.grid {
                    Some((xi, yi)) => text(format_args!(
                        "target: ({x_cm}, {y_cm}) cm grid ({xi}, {yi})"
                    )),
                    None => text(format_args!("target: ({x_cm}, {y_cm}) cm")),
                }
            }
            7 => {
                let (_, aim) = s.target?;
                text(format_args!(
                    "joint: yaw {} deg pitch {} deg",
                    Fixed::<3>(aim.yaw_deg),
                    Fixed::<3>(aim.pitch_deg)
                ))
            }
            8 => {
                let (_, aim) = s.target?;
                text(format_args!(
                    "servo: yaw {} deg pitch {} deg (wire {} {})",
                    Fixed::<1>(f64::from(aim.yaw_wire) / 10.0),
                    Fixed::<1>(f64::from(aim.pitch_wire) / 10.0),
                    aim.yaw_wire,
                    aim.pitch_wire
                ))
            }
            9 => {
                let (yaw, pitch) = self.measured?;
                text(format_args!(
                    "measured at arrival: yaw {} deg pitch {} deg",
                    Fixed::<1>(f64::from(yaw) / 10.0),
                    Fixed::<1>(f64::from(pitch) / 10.0)
                ))
            }
            10 => text(format_args!(
                "laser: {} (mode {})",
                if s.laser_on { "on" } else { "off" },
                self.settings.laser_mode.name()
            )),
            11 => match s.faulty_servo {
                Some(id) => text(format_args!("faults: servo {id} not responding")),
                None => text(format_args!("faults: none")),
            },
            12 => text(format_args!(
                "servo readings rejected as implausible: {}",
                self.servo
                    .implausible_readings
                    .load(core::sync::atomic::Ordering::Relaxed)
            )),
            _ => None,
        }
    }
}

/// Points a pattern check aims at per executor step. One gimbal IK point
/// is ~170 µs of soft-float on the target; with the first point of the
/// run aimed in the last step, a step aims at no more than four (~0.7 ms).
const CHECKS_PER_STEP: usize = 3;

/// Lines [`Sequencer::status_line`] knows.
const STATUS_LINES: usize = 13;

impl Run {
    pub(super) fn new(pattern: Option<Pattern>, single: Option<Target>, once: bool) -> Self {
        Self {
            pattern,
            single,
            once,
            index: 0,
            path: None,
            pass: 0,
            phase: Phase::Moving,
            seq: 0,
            dwell_until: None,
            gimbal_busy: false,
            galvo_busy: false,
            galvo_seq: 0,
        }
    }
}
