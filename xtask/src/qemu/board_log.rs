//! The emulated board's log channel (UART2): what the firmware logged and
//! the `@` reports of its laser pin, LEDs and laser-deciding events, each
//! with the board's time (µs since its boot, embassy-time). See
//! `firmware/qemu-m4/src/log_channel.rs` for the line format.

use std::io::{BufRead, BufReader};
use std::os::unix::net::UnixStream;
use std::sync::{Arc, Condvar, Mutex};

/// A sequencer event that decides whether a laser may be lit (laser-app's
/// `LaserEvent`, as the board reports it).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BoardEvent {
    /// The sequencer stopped; why, as logged.
    Stopped(String),
    /// A pattern or goto started.
    RunStarted,
    /// A servo move was sent.
    GimbalMoveSent,
    /// The gimbal's arrival was accepted.
    GimbalArrived,
}

/// One parsed line of the log channel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LogLine {
    /// `@laser 0` or `@laser 1 <‰>`: the laser output's level, ‰.
    Laser(u64, u16),
    /// `@event …`.
    Event(u64, BoardEvent),
    /// `@leds …` (the text after `@leds`).
    Leds(u64, String),
    /// `@stats …` (the text after `@stats`).
    Stats(u64, String),
    /// Anything else: a log record (level and message).
    Log(u64, String),
}

/// Parses one line of the log channel; `None` for a line without a time
/// stamp (a line cut short by a reset, say).
pub fn parse_line(line: &str) -> Option<LogLine> {
    let (t, rest) = line.trim_end().split_once(' ')?;
    let t: u64 = t.parse().ok()?;
    let parsed = if let Some(v) = rest.strip_prefix("@laser ") {
        let mut words = v.split(' ');
        let level = match (words.next(), words.next()) {
            (Some("1"), Some(level)) => level.parse().unwrap_or(1000),
            (Some("1"), None) => 1000,
            _ => 0,
        };
        LogLine::Laser(t, level)
    } else if let Some(e) = rest.strip_prefix("@event ") {
        let event = match e {
            "run-started" => BoardEvent::RunStarted,
            "move-sent" => BoardEvent::GimbalMoveSent,
            "arrived" => BoardEvent::GimbalArrived,
            other => BoardEvent::Stopped(other.strip_prefix("stopped ").unwrap_or(other).into()),
        };
        LogLine::Event(t, event)
    } else if let Some(leds) = rest.strip_prefix("@leds ") {
        LogLine::Leds(t, leds.to_owned())
    } else if let Some(stats) = rest.strip_prefix("@stats ") {
        LogLine::Stats(t, stats.to_owned())
    } else {
        LogLine::Log(t, rest.to_owned())
    };
    Some(parsed)
}

/// Everything the log channel said, in board time. Board time restarts at
/// each boot: [`BoardLog::boots`] marks where, and times are kept
/// continuous by adding the previous boots' last stamps.
#[derive(Debug, Default, Clone)]
pub struct BoardLog {
    /// Laser pin switches: (board µs, lit).
    pub laser_events: Vec<(u64, bool)>,
    /// Laser output levels as reported: (board µs, ‰; 0 dark).
    pub laser_power: Vec<(u64, u16)>,
    /// Laser-deciding events: (board µs, event).
    pub events: Vec<(u64, BoardEvent)>,
    /// LED changes: (board µs, `heartbeat=… laser=… fault=…`).
    pub leds: Vec<(u64, String)>,
    /// Log records: (board µs, `LEVEL message`).
    pub logs: Vec<(u64, String)>,
    /// laser-app's defmt logs, decoded (`defmt-log` images, UART3).
    pub defmt_lines: Vec<String>,
    /// The board's measurement reports (the text after `@stats`).
    pub stats: Vec<String>,
    /// Boots seen.
    pub boots: usize,
    /// Boots after which the executor ran a task (the indicator task's
    /// first `@leds` report).
    pub ready_boots: usize,
    /// Time of the last line, continuous over boots, µs.
    pub last_us: u64,
    /// Offset added to this boot's stamps, µs.
    boot_offset_us: u64,
}

impl BoardLog {
    /// Adds one line of the channel.
    pub fn push(&mut self, line: &str) {
        let Some(parsed) = parse_line(line) else {
            return;
        };
        let raw_t = match &parsed {
            LogLine::Laser(t, _)
            | LogLine::Event(t, _)
            | LogLine::Leds(t, _)
            | LogLine::Stats(t, _)
            | LogLine::Log(t, _) => *t,
        };
        if let LogLine::Log(_, text) = &parsed
            && text.contains("booting on QEMU")
        {
            if self.boots > 0 {
                self.boot_offset_us = self.last_us;
            }
            self.boots += 1;
        }
        if matches!(parsed, LogLine::Leds(..)) && self.ready_boots < self.boots {
            self.ready_boots = self.boots;
        }
        let t = self.boot_offset_us + raw_t;
        self.last_us = self.last_us.max(t);
        match parsed {
            LogLine::Laser(_, level) => {
                if self.laser_lit() != (level > 0) {
                    self.laser_events.push((t, level > 0));
                }
                self.laser_power.push((t, level));
            }
            LogLine::Event(_, e) => self.events.push((t, e)),
            LogLine::Leds(_, l) => self.leds.push((t, l)),
            LogLine::Stats(_, text) => self.stats.push(text),
            LogLine::Log(_, text) => self.logs.push((t, text)),
        }
    }

    /// The laser pin's state as last reported.
    pub fn laser_lit(&self) -> bool {
        self.laser_events.last().is_some_and(|(_, on)| *on)
    }

    /// The laser output's level as last reported, ‰.
    pub fn laser_level(&self) -> u16 {
        self.laser_power.last().map_or(0, |(_, level)| *level)
    }
}

/// The log as it arrives, and a signal for each line.
pub type SharedLog = Arc<(Mutex<BoardLog>, Condvar)>;

/// Reads the log channel until QEMU closes it, printing the log records on
/// stderr (`echo`) and recording everything into `log`.
pub fn read_channel(stream: UnixStream, log: SharedLog, echo: bool) {
    for line in BufReader::new(stream).split(b'\n').map_while(Result::ok) {
        let line = String::from_utf8_lossy(&line).into_owned();
        if echo && let Some(LogLine::Log(t, text)) = parse_line(&line) {
            eprintln!("[board {:>10.6} s] {text}", t as f64 / 1e6);
        }
        let (lock, signal) = &*log;
        if let Ok(mut board) = lock.lock() {
            board.push(&line);
        }
        signal.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_parse_into_reports_and_logs() {
        assert_eq!(parse_line("12 @laser 1 300"), Some(LogLine::Laser(12, 300)));
        assert_eq!(parse_line("12 @laser 1"), Some(LogLine::Laser(12, 1000)));
        assert_eq!(parse_line("12 @laser 0"), Some(LogLine::Laser(12, 0)));
        assert_eq!(
            parse_line("13 @event stopped servo fault"),
            Some(LogLine::Event(
                13,
                BoardEvent::Stopped("servo fault".into())
            ))
        );
        assert_eq!(
            parse_line("14 @event arrived"),
            Some(LogLine::Event(14, BoardEvent::GimbalArrived))
        );
        assert_eq!(
            parse_line("15 INFO console: host connected"),
            Some(LogLine::Log(15, "INFO console: host connected".into()))
        );
        assert_eq!(parse_line("garbage"), None);
        assert_eq!(parse_line("x @laser 1"), None);
    }

    #[test]
    fn board_time_stays_continuous_across_a_reset() {
        let mut log = BoardLog::default();
        for line in [
            "0 INFO laser-pointer booting on QEMU mps2-an386",
            "500 @laser 1 1000",
            "700 @laser 1 300",
            "900 @laser 0",
            "0 INFO laser-pointer booting on QEMU mps2-an386",
            "100 @laser 1 1000",
        ] {
            log.push(line);
        }
        assert_eq!(log.boots, 2);
        assert_eq!(log.ready_boots, 0, "no task has run");
        assert_eq!(
            log.laser_events,
            vec![(500, true), (900, false), (1000, true)]
        );
        assert!(log.laser_lit());
        assert_eq!(
            log.laser_power,
            vec![(500, 1000), (700, 300), (900, 0), (1000, 1000)]
        );
        assert_eq!(log.laser_level(), 1000);
    }
}
