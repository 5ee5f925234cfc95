//! What the grbl session reports: status reports (`?`), `$$`, `$#`,
//! `$G`, `$I`, `$N` and `$` help, formatted by [`crate::grbl::report`].

use crate::grbl::report::{self, MachineState, Status};
use crate::grbl::system::SystemCommand;
use crate::grbl::{Alarm, GrblError, ParserState};
use crate::sequencer::gcode::power::Seen;
use crate::sequencer::gcode::queue::{Hold, PLANNER_BLOCKS};
use crate::sequencer::gcode::{GcodeSession, GrblMode, RX_BUFFER_BYTES};
use crate::sequencer::io::{Action, ActionSink, Line};
use crate::settings::Settings;
use crate::text::{ReplyText, reply_text};

/// A data line of the reply in grbl's form (no decoration).
pub(in crate::sequencer) fn data(out: &mut dyn ActionSink, text: ReplyText) {
    out.act(Action::Line(Line::Data(text)));
}

/// A grbl push message (a status report, `ALARM:N`, the banner): printed
/// bare, never part of the reply of the command in flight (which may be
/// the PELCO port's quiet one).
pub(in crate::sequencer) fn push(out: &mut dyn ActionSink, text: ReplyText) {
    out.act(Action::Line(Line::Push(text)));
}

/// `ALARM:N` as a push message.
pub(in crate::sequencer) fn alarm(out: &mut dyn ActionSink, alarm: Alarm) {
    let mut text = ReplyText::new();
    // Fits: `ALARM:` and a one- or two-digit code.
    let _ = report::write_alarm(&mut text, alarm);
    push(out, text);
}

/// A notice line (`[MSG:…]` and the like).
pub(in crate::sequencer) fn notice(out: &mut dyn ActionSink, args: core::fmt::Arguments<'_>) {
    out.act(Action::Line(Line::Notice(reply_text(args))));
}

/// Closes the current reply with `ok`.
pub(in crate::sequencer) fn ok(out: &mut dyn ActionSink) {
    out.act(Action::Line(Line::Ok));
}

/// Closes the current reply with `error:N`.
pub(in crate::sequencer) fn error(out: &mut dyn ActionSink, error: GrblError) {
    out.act(Action::Line(Line::GrblError(error)));
}

impl GcodeSession {
    /// The `$` commands that only report (`$`, `$$`, `$#`, `$G`, `$I`,
    /// `$N`): their data lines (`$$` reads the product's `settings`).
    pub(in crate::sequencer) fn info(
        &self,
        command: SystemCommand<'_>,
        settings: &Settings,
        out: &mut dyn ActionSink,
    ) {
        match command {
            SystemCommand::Help => data(out, reply_text(format_args!("{}", report::HELP))),
            SystemCommand::Settings => {
                for setting in crate::grbl::settings_map::SETTINGS {
                    let value = self.setting_value(setting, settings);
                    data(
                        out,
                        reply_text(format_args!("{}", SettingLine(setting, value))),
                    );
                }
            }
            SystemCommand::Parameters => {
                for index in 0..report::PARAMETER_LINES {
                    let p = &self.parser;
                    data(out, reply_text(format_args!("{}", ParameterLine(index, p))));
                }
            }
            SystemCommand::ParserState => {
                data(
                    out,
                    reply_text(format_args!("{}", ParserLine(&self.parser))),
                );
            }
            SystemCommand::BuildInfo => {
                let version = reply_text(format_args!(
                    "[VER:1.1h.{}:{}]",
                    crate::build_info::VERSION,
                    crate::build_info::PRODUCT
                ));
                data(out, version);
                // As u32: the u16 writer is not linked (text::Int).
                let rx_bytes = u32::from(RX_BUFFER_BYTES);
                let options = reply_text(format_args!("[OPT:VN,{PLANNER_BLOCKS},{rx_bytes}]"));
                data(out, options);
            }
            SystemCommand::StartupLines => {
                data(out, reply_text(format_args!("$N0=")));
                data(out, reply_text(format_args!("$N1=")));
            }
            _ => {}
        }
    }

    /// `?`: one status report, whatever the state (`rx_free_bytes`: room
    /// in the console's RX buffer). The caller counts it
    /// ([`Self::count_report`]) once it is sent.
    pub(in crate::sequencer) fn status(&self, rx_free_bytes: u16, seen: &Seen<'_>) -> ReplyText {
        let g = self;
        let motion = &g.motion;
        let state = match (g.mode, motion.hold) {
            // A `$H` waiting for the stepper's homing (grbl's `Home`).
            _ if g.homing || seen.stepper_homing => MachineState::Home,
            (GrblMode::Alarm, _) => MachineState::Alarm,
            (GrblMode::Check, _) => MachineState::Check,
            (_, Hold::Held) => MachineState::Hold {
                decelerating: false,
            },
            (_, Hold::Stopping) => MachineState::Hold { decelerating: true },
            // The laser controls keep the laser off (grbl's safety door).
            _ if seen.door.is_some() => MachineState::Door(seen.door.unwrap_or(0)),
            _ if motion.jogging() => MachineState::Jog,
            _ if motion.is_idle() => MachineState::Idle,
            _ => MachineState::Run,
        };
        let (mut feed, _) = motion.feed_and_power(&g.overrides, &seen.jobs.gimbal);
        let power = self.reported_power(seen);
        // A driver may mark at most at its marking speed.
        feed = feed.min(seen.drivers.feed_cap_mm_min(seen.settings));
        let mask = g.values.report_mask;
        let free_blocks = (PLANNER_BLOCKS - motion.queue.len()) as u16;
        let status = Status {
            state,
            machine_mm: motion.position,
            work_offset_mm: g.parser.work_offset(),
            report_machine: mask & 1 != 0,
            buffer: (mask & 2 != 0).then_some((free_blocks, rx_free_bytes)),
            line_number: None,
            feed_mm_min: feed,
            power,
            show_work_offset: self.reports.is_multiple_of(10),
            overrides: (self.reports % 10 == 1).then_some((
                g.overrides,
                g.parser.spindle,
                g.parser.coolant,
            )),
        };
        reply_text(format_args!("{}", StatusLine(&status)))
    }

    /// A status report was sent (grbl adds `WCO:` / `Ov:` every few).
    pub(in crate::sequencer) fn count_report(&mut self) {
        self.reports = self.reports.wrapping_add(1);
    }
}

/// Adapters from the report writers to `Display`.
struct StatusLine<'a>(&'a Status);
struct ParserLine<'a>(&'a ParserState);
struct ParameterLine<'a>(usize, &'a ParserState);
struct SettingLine<'a>(&'a crate::grbl::settings_map::GrblSetting, f64);

impl core::fmt::Display for StatusLine<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        report::write_status(f, self.0)
    }
}

impl core::fmt::Display for ParserLine<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        report::write_parser_state(f, self.0)
    }
}

impl core::fmt::Display for ParameterLine<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        report::write_parameter_line(f, self.0, self.1)
    }
}

impl core::fmt::Display for SettingLine<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        report::write_setting(f, self.0, self.1)
    }
}
