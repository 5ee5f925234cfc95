//! The accepted settings over time, for the rules that depend on them.

use laser_app::cli::parse::parse_line;
use laser_app::command::Command;
use laser_app::settings::{LaserMode, Settings};

use crate::usb_host::Transcript;
/// The accepted settings over time, replayed from the transcript with the
/// firmware's own parser: `(sent µs, replied µs, settings after)`.
pub(super) struct SettingsTimeline {
    changes: Vec<(u64, u64, Settings)>,
}

impl SettingsTimeline {
    pub(super) fn from_transcript(transcript: &Transcript) -> Self {
        let mut settings = Settings::default();
        let mut changes = Vec::new();
        let mut pending: Option<(u64, Command)> = None;
        for (t, line) in &transcript.lines {
            if let Some(sent) = line.strip_prefix("> ") {
                pending = match parse_line(sent) {
                    Ok(Some(c @ (Command::Set { .. } | Command::Laser(_)))) => Some((*t, c)),
                    _ => None,
                };
                continue;
            }
            let accepted = line == "ok";
            if !(accepted || line.starts_with("error:")) {
                continue;
            }
            let Some((sent, command)) = pending.take() else {
                continue;
            };
            if !accepted {
                continue;
            }
            match command {
                Command::Set { param, value } => {
                    if settings.set(param, value).is_err() {
                        continue;
                    }
                }
                Command::Laser(mode) => settings.laser_mode = mode,
                _ => continue,
            }
            changes.push((sent, *t, settings));
        }
        Self { changes }
    }

    /// Largest marking speed in force at any time up to `t_us`, mm/s.
    pub(super) fn max_mark_speed_mm_s(&self, t_us: u64) -> f64 {
        self.changes
            .iter()
            .take_while(|(sent, _, _)| *sent <= t_us)
            .map(|(_, _, s)| s.galvo.mark_speed_mm_s)
            .fold(Settings::default().galvo.mark_speed_mm_s, f64::max)
    }

    /// Largest arrival deadband in force at any time up to `t_us`, deg.
    pub(super) fn max_deadband_deg(&self, t_us: u64) -> f64 {
        self.changes
            .iter()
            .take_while(|(sent, _, _)| *sent <= t_us)
            .map(|(_, _, s)| s.deadband_deg)
            .fold(Settings::default().deadband_deg, f64::max)
    }

    /// Whether `laser dwell` mode is certainly in force at `t_us`: the
    /// last accepted change replied before then set it, and a change in
    /// flight at `t_us` (sent by then, replied at or after it: the
    /// transcript cannot order it against what happened in that instant)
    /// keeps it.
    pub(super) fn certainly_dwell_mode(&self, t_us: u64) -> bool {
        let mut mode = Settings::default().laser_mode;
        for (sent, replied, s) in &self.changes {
            if *sent > t_us {
                break;
            }
            if *replied >= t_us && (mode != LaserMode::Dwell || s.laser_mode != LaserMode::Dwell) {
                return false;
            }
            mode = s.laser_mode;
        }
        mode == LaserMode::Dwell
    }

    /// Smallest emission indicator delay in force at any time up to
    /// `t_us`, s.
    pub(super) fn min_emission_delay_s(&self, t_us: u64) -> f64 {
        self.changes
            .iter()
            .take_while(|(sent, _, _)| *sent <= t_us)
            .map(|(_, _, s)| s.emission_delay_s)
            .fold(Settings::default().emission_delay_s, f64::min)
    }
}
