//! What the grbl session reports: status reports (`?`), `$$`, `$#`,
//! `$G`, `$I`, `$N` and `$` help, formatted by [`crate::grbl::report`].

use crate::grbl::ParserState;
use crate::grbl::report::{self, MachineState, Status};
use crate::grbl::system::SystemCommand;
use crate::sequencer::gcode::queue::{Hold, PLANNER_BLOCKS};
use crate::sequencer::gcode::{GrblMode, RX_BUFFER_BYTES};
use crate::sequencer::machine::{ActionSink, Core};
use crate::text::reply_text;

impl Core {
    /// The `$` commands that only report (`$`, `$$`, `$#`, `$G`, `$I`,
    /// `$N`): their data lines.
    pub(in crate::sequencer) fn grbl_info(
        &mut self,
        command: SystemCommand<'_>,
        out: &mut dyn ActionSink,
    ) {
        match command {
            SystemCommand::Help => {
                self.grbl_data(out, reply_text(format_args!("{}", report::HELP)))
            }
            SystemCommand::Settings => self.grbl_report_settings(out),
            SystemCommand::Parameters => {
                for index in 0..report::PARAMETER_LINES {
                    let p = &self.gcode.parser;
                    let text = reply_text(format_args!("{}", ParameterLine(index, p)));
                    self.grbl_data(out, text);
                }
            }
            SystemCommand::ParserState => {
                let text = reply_text(format_args!("{}", ParserLine(&self.gcode.parser)));
                self.grbl_data(out, text);
            }
            SystemCommand::BuildInfo => {
                let version = reply_text(format_args!(
                    "[VER:1.1h.{}:{}]",
                    crate::build_info::VERSION,
                    crate::build_info::PRODUCT
                ));
                self.grbl_data(out, version);
                // As u32: the u16 writer is not linked (text::Int).
                let rx_bytes = u32::from(RX_BUFFER_BYTES);
                let options = reply_text(format_args!("[OPT:VN,{PLANNER_BLOCKS},{rx_bytes}]"));
                self.grbl_data(out, options);
            }
            SystemCommand::StartupLines => {
                self.grbl_data(out, reply_text(format_args!("$N0=")));
                self.grbl_data(out, reply_text(format_args!("$N1=")));
            }
            _ => {}
        }
    }

    /// `?`: one status report, whatever the state.
    pub(in crate::sequencer) fn grbl_status(
        &mut self,
        rx_free_bytes: u16,
        out: &mut dyn ActionSink,
    ) {
        let g = &self.gcode;
        let motion = &g.motion;
        let state = match (g.mode, motion.hold) {
            // A `$H` waiting for the stepper's homing (grbl's `Home`).
            _ if g.homing || self.stepper_homing => MachineState::Home,
            (GrblMode::Alarm, _) => MachineState::Alarm,
            (GrblMode::Check, _) => MachineState::Check,
            (_, Hold::Held) => MachineState::Hold {
                decelerating: false,
            },
            (_, Hold::Stopping) => MachineState::Hold { decelerating: true },
            // The laser controls keep the laser off (grbl's safety door).
            _ if self.door_substate().is_some() => {
                MachineState::Door(self.door_substate().unwrap_or(0))
            }
            _ if motion.jogging() => MachineState::Jog,
            _ if motion.is_idle() => MachineState::Idle,
            _ => MachineState::Run,
        };
        let (mut feed, _) = motion.feed_and_power(&g.overrides, &self.jobs.gimbal);
        let power = self.gcode_reported_power();
        // A driver may mark at most at its marking speed.
        feed = feed.min(self.drivers().feed_cap_mm_min(&self.settings));
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
            show_work_offset: self.gcode.reports.is_multiple_of(10),
            overrides: (self.gcode.reports % 10 == 1).then_some((
                g.overrides,
                g.parser.spindle,
                g.parser.coolant,
            )),
        };
        let text = reply_text(format_args!("{}", StatusLine(&status)));
        self.gcode.reports = self.gcode.reports.wrapping_add(1);
        self.grbl_data(out, text);
    }

    /// `$$`.
    fn grbl_report_settings(&mut self, out: &mut dyn ActionSink) {
        for setting in crate::grbl::settings_map::SETTINGS {
            let value = self.gcode.setting_value(setting, &self.settings);
            let text = reply_text(format_args!("{}", SettingLine(setting, value)));
            self.grbl_data(out, text);
        }
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
