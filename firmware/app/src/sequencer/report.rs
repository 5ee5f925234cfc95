//! The data lines of `help`, `version`, `get` and `status`: text from the
//! core's state (and, for `status`, what the shell read from the links).

use crate::build_info;
use crate::command::{Command, HELP_LINES};
use crate::domain::{AimModel, PointCm};
use crate::sequencer::machine::{ActionSink, Core, Readings};
use crate::status::{Activity, Phase, Snapshot};
use crate::text::{Fixed, Int};

impl Core {
    /// The data lines of `command` (`help`, `version`, `status`, `get`).
    pub(super) fn report(&self, command: Command, readings: &Readings, out: &mut dyn ActionSink) {
        match command {
            Command::Help => {
                for line in HELP_LINES {
                    self.data(out, format_args!("{line}"));
                }
            }
            Command::Version => self.data(
                out,
                format_args!(
                    "{} {} (git {}, {} build for {})",
                    build_info::PRODUCT,
                    build_info::VERSION,
                    build_info::GIT_REV,
                    build_info::PROFILE,
                    build_info::TARGET
                ),
            ),
            Command::Status => {
                let s = self.status();
                self.status_run_lines(&s, out);
                self.status_aim_lines(&s, out);
                self.status_health_lines(&s, readings, out);
            }
            Command::Get(param) => self.param_line(param, out),
            _ => {}
        }
    }

    /// `status`: uptime, build, what runs, how.
    fn status_run_lines(&self, s: &Snapshot, out: &mut dyn ActionSink) {
        let uptime_ms = self
            .inputs
            .now
            .saturating_duration_since(self.booted_at)
            .as_millis();
        self.data(
            out,
            format_args!("uptime: {}.{:03} s", uptime_ms / 1000, uptime_ms % 1000),
        );
        self.data(
            out,
            format_args!(
                "build: {} {} git {} {}",
                build_info::PRODUCT,
                build_info::VERSION,
                build_info::GIT_REV,
                build_info::PROFILE
            ),
        );
        match s.activity {
            Activity::Idle => self.data(out, format_args!("state: idle")),
            Activity::Goto => self.data(out, format_args!("state: goto")),
            Activity::Gcode => self.data(out, format_args!("state: G-code")),
            Activity::Homing => self.data(out, format_args!("state: homing")),
            Activity::Pattern(p) => self.data(
                out,
                format_args!(
                    "state: pattern {}{} point {} pass {}",
                    p.name(),
                    if self.run.is_some_and(|r| r.kind.once()) {
                        " once"
                    } else {
                        ""
                    },
                    s.point_index.unwrap_or(0),
                    s.pass
                ),
            ),
        }
        let phase = match s.phase {
            None => "-",
            Some(Phase::Approaching) => "approaching",
            Some(Phase::Moving) => "moving",
            Some(Phase::Dwelling) => "dwelling",
            Some(Phase::Holding) => "holding",
        };
        self.data(out, format_args!("phase: {phase}"));
        self.data(out, format_args!("actuator: {}", self.actuator.name()));
        let model = match self.model {
            AimModel::Exact => "exact",
            AimModel::Seed => "seed",
        };
        self.data(out, format_args!("model: {model}"));
    }

    /// `status`: the last target, its aim, and the angles measured at the
    /// last arrival (each only when there is one).
    fn status_aim_lines(&self, s: &Snapshot, out: &mut dyn ActionSink) {
        if let Some((target, aim)) = s.target {
            let PointCm { x_cm, y_cm } = target.point;
            let (x_cm, y_cm) = (Fixed::<3>(x_cm), Fixed::<3>(y_cm));
            match target.grid {
                Some((xi, yi)) => {
                    let (xi, yi) = (Int(xi.into()), Int(yi.into()));
                    self.data(
                        out,
                        format_args!("target: ({x_cm}, {y_cm}) cm grid ({xi}, {yi})"),
                    )
                }
                None => self.data(out, format_args!("target: ({x_cm}, {y_cm}) cm")),
            }
            self.data(
                out,
                format_args!(
                    "joint: yaw {} deg pitch {} deg",
                    Fixed::<3>(aim.yaw_deg),
                    Fixed::<3>(aim.pitch_deg)
                ),
            );
            self.data(
                out,
                format_args!(
                    "servo: yaw {} deg pitch {} deg (wire {} {})",
                    Fixed::<1>(f64::from(aim.yaw_wire) / 10.0),
                    Fixed::<1>(f64::from(aim.pitch_wire) / 10.0),
                    Int(aim.yaw_wire.into()),
                    Int(aim.pitch_wire.into())
                ),
            );
        }
        if let Some((yaw, pitch)) = self.measured {
            self.data(
                out,
                format_args!(
                    "measured at arrival: yaw {} deg pitch {} deg",
                    Fixed::<1>(f64::from(yaw) / 10.0),
                    Fixed::<1>(f64::from(pitch) / 10.0)
                ),
            );
        }
    }

    /// `status`: laser, faults, rejected servo readings.
    fn status_health_lines(&self, s: &Snapshot, readings: &Readings, out: &mut dyn ActionSink) {
        self.data(
            out,
            format_args!(
                "laser: {} (mode {})",
                if s.laser_on { "on" } else { "off" },
                self.settings.laser_mode.name()
            ),
        );
        match s.faulty_servo {
            Some(id) => {
                let id = u32::from(id);
                self.data(out, format_args!("faults: servo {id} not responding"))
            }
            None => self.data(out, format_args!("faults: none")),
        }
        self.data(
            out,
            format_args!(
                "servo readings rejected as implausible: {}",
                readings.implausible_readings
            ),
        );
    }
}
