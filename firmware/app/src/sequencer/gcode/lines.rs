//! G-code and `$` lines and realtime commands of the session.

use crate::command::RealtimeRequest;
use crate::grbl::classify::{LineKind, classify};
use crate::grbl::realtime::Realtime;
use crate::grbl::system::{RestoreScope, SystemCommand, parse_system};
use crate::grbl::{Alarm, Block, Blocks, GrblError};
use crate::sequencer::drivers::Driver;
use crate::sequencer::gcode::context::Session;
use crate::sequencer::gcode::queue::Hold;
use crate::sequencer::gcode::report;
use crate::sequencer::gcode::settings::Written;
use crate::sequencer::gcode::{GrblMode, GrblValues, NO_OVERRIDES};
use crate::sequencer::io::ActionSink;
use crate::settings::Settings;
use crate::text::reply_text;

impl Session<'_> {
    /// A G-code or `$` line from the console: closed with `ok` (for a
    /// motion, once it is queued) or `error:N`.
    pub(in crate::sequencer) fn line(&mut self, line: &str, out: &mut dyn ActionSink) {
        match classify(line) {
            LineKind::System => self.system_line(line, out),
            _ => self.gcode_line(line, out),
        }
    }

    /// `ALARM:N`, the machine locked; motion stopped, laser dark.
    pub(in crate::sequencer) fn alarm(&mut self, alarm: Alarm, out: &mut dyn ActionSink) {
        self.stop("grbl alarm", out);
        self.gcode.mode = GrblMode::Alarm;
        report::alarm(out, alarm);
    }

    fn gcode_line(&mut self, line: &str, out: &mut dyn ActionSink) {
        if self.gcode.mode == GrblMode::Alarm || self.gcode.motion.jogging() {
            return report::error(out, GrblError::GcodeLock);
        }
        let before = self.gcode.parser;
        let blocks = match self.gcode.parser.execute(line) {
            Ok(blocks) => blocks,
            Err(e) => return report::error(out, e),
        };
        if !blocks.iter().all(|b| self.block_reachable(b)) {
            self.gcode.parser = before;
            self.alarm(Alarm::SoftLimit, out);
            report::ok(out);
            return;
        }
        self.queue_blocks(blocks, out);
    }

    /// Queues `blocks` and answers `ok`, or keeps them until the queue has
    /// room (the `ok` then waits: back-pressure to the sender).
    fn queue_blocks(&mut self, blocks: Blocks, out: &mut dyn ActionSink) {
        if self.gcode.mode == GrblMode::Check || blocks.is_empty() {
            return report::ok(out);
        }
        self.gcode.motion.owed = Some(blocks);
        self.gcode.take_owed(out);
        self.advance(out);
        self.galvo_send_ahead(out);
        if self.drivers().gimbal_streams() {
            self.with_stage(out, |st, jobs, _| jobs.gimbal.remember(st));
        }
    }

    fn system_line(&mut self, line: &str, out: &mut dyn ActionSink) {
        let command = match parse_system(line) {
            Ok(command) => command,
            Err(e) => return report::error(out, e),
        };
        let idle = self.gcode.motion.is_idle();
        match command {
            SystemCommand::Help
            | SystemCommand::Settings
            | SystemCommand::Parameters
            | SystemCommand::ParserState
            | SystemCommand::BuildInfo
            | SystemCommand::StartupLines => self.gcode.info(command, self.settings, out),
            SystemCommand::CheckMode => return self.gcode.check_mode(idle, out),
            SystemCommand::Unlock => {
                if self.gcode.mode == GrblMode::Alarm {
                    self.gcode.mode = GrblMode::Normal;
                    report::notice(out, format_args!("MSG:Caution: Unlocked"));
                }
            }
            SystemCommand::Home => return self.home(idle, out),
            SystemCommand::Sleep => {
                self.stop("grbl sleep", out);
                self.gcode.sync_position();
            }
            SystemCommand::Jog(text) => return self.jog(text, out),
            SystemCommand::Restore(scope) => {
                if !idle {
                    return report::error(out, GrblError::NotIdle);
                }
                if matches!(scope, RestoreScope::Settings | RestoreScope::All) {
                    self.gcode.values = GrblValues::default();
                    self.settings.gcode_junction_mm = Settings::default().gcode_junction_mm;
                    // `$11` is also the galvo loop's marking junction.
                    self.configure_galvo(out);
                }
                if matches!(scope, RestoreScope::Offsets | RestoreScope::All) {
                    self.gcode.parser.g54 = crate::grbl::PointMm::ZERO;
                    self.gcode.parser.g92 = crate::grbl::PointMm::ZERO;
                }
                report::notice(out, format_args!("MSG:Restoring defaults"));
            }
            SystemCommand::SetSetting { number, value } => {
                if !idle {
                    return report::error(out, GrblError::NotIdle);
                }
                match self.gcode.set_setting(number, value, self.settings) {
                    Ok(Written::Session) => {}
                    Ok(Written::Product) => self.configure_galvo(out),
                    Err(e) => return report::error(out, e),
                }
            }
        }
        report::ok(out);
    }

    /// `$H`: no switches to home on; aims at the board origin (dark) and
    /// unlocks an alarm.
    fn home(&mut self, idle: bool, out: &mut dyn ActionSink) {
        if !idle || self.gcode.mode == GrblMode::Check {
            return report::error(out, GrblError::NotIdle);
        }
        if self.drivers().any(Driver::homes_with_switches) {
            // The reply waits for the end of homing (grbl's `$H`): a
            // sender's next lines wait with it.
            return match self.start_homing(out) {
                Ok(()) => self.gcode.homing = true,
                Err(_) => report::error(out, GrblError::HomingDisabled),
            };
        }
        self.gcode.mode = GrblMode::Normal;
        let from = self.gcode.motion.position;
        self.gcode.parser.position = crate::grbl::PointMm::ZERO;
        let mut blocks = Blocks::new();
        if from != crate::grbl::PointMm::ZERO {
            let _ = blocks.push(Block::Rapid {
                from,
                to: crate::grbl::PointMm::ZERO,
            });
        }
        self.queue_blocks(blocks, out);
    }

    /// `$J=`: a jog, dark; refused beyond the reachable workspace
    /// (error:15, no alarm, as grbl with soft limits). As grbl 1.1, only
    /// when idle or jogging: otherwise (a job running, a hold, an alarm,
    /// check mode) error:8.
    fn jog(&mut self, text: &str, out: &mut dyn ActionSink) {
        let busy = !self.gcode.motion.is_idle() && !self.gcode.motion.jogging();
        if self.gcode.mode != GrblMode::Normal || busy {
            return report::error(out, GrblError::NotIdle);
        }
        let before = self.gcode.parser;
        let jog = match self.gcode.parser.jog(text) {
            Ok(jog) => jog,
            Err(e) => return report::error(out, e),
        };
        let mut blocks = Blocks::new();
        if let Some(block) = jog {
            if !self.block_reachable(&block) {
                self.gcode.parser = before;
                return report::error(out, GrblError::TravelExceeded);
            }
            let _ = blocks.push(block);
        }
        self.queue_blocks(blocks, out);
    }

    /// A realtime command from the console.
    pub(in crate::sequencer) fn realtime(
        &mut self,
        request: RealtimeRequest,
        out: &mut dyn ActionSink,
    ) {
        let before = self.gcode.overrides;
        let ov = &mut self.gcode.overrides;
        match request.command {
            Realtime::StatusReport => {
                let text = self.gcode.status(request.rx_free_bytes, &self.seen());
                self.gcode.count_report();
                report::push(out, text);
            }
            Realtime::FeedHold => self.hold(out),
            Realtime::CycleStart => self.resume(out),
            Realtime::SoftReset => self.soft_reset(out),
            Realtime::JogCancel => self.jog_cancel(out),
            Realtime::FeedOverride(step) => {
                ov.feed = step.apply(ov.feed, 10, 200);
                self.stepper_override(out);
            }
            Realtime::RapidOverride(percent) => ov.rapid = percent,
            Realtime::SpindleOverride(step) => ov.spindle = step.apply(ov.spindle, 10, 200),
            Realtime::SpindleStop | Realtime::Ignored(_) => {}
        }
        self.gcode.note_overrides(before);
    }

    /// 0x18: everything stops at once, laser dark; the parser's modes
    /// reset (position, offsets and settings kept); ALARM:3 if it
    /// interrupted motion.
    fn soft_reset(&mut self, out: &mut dyn ActionSink) {
        let moving = self.gcode.motion.current.is_some() && self.gcode.motion.hold != Hold::Held;
        // grbl's reset kills the motion at once where a driver can (the
        // position is then uncertain: ALARM:3); `stop` would brake.
        self.drivers_reset(out);
        self.stop("grbl soft reset", out);
        self.gcode.parser.soft_reset();
        self.gcode.sync_position();
        self.gcode.overrides = NO_OVERRIDES;
        if self.gcode.mode == GrblMode::Check {
            self.gcode.mode = GrblMode::Normal;
        }
        if moving {
            self.gcode.mode = GrblMode::Alarm;
            report::alarm(out, Alarm::ResetWhileMoving);
        }
        report::push(
            out,
            reply_text(format_args!("{}", crate::grbl::report::BANNER)),
        );
        if self.gcode.mode == GrblMode::Alarm {
            report::notice(out, format_args!("MSG:'$H'|'$X' to unlock"));
        }
    }
}
