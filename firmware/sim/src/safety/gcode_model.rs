//! The commanded G-code toolpath, interpreted from the transcript here,
//! independently of the firmware's parser and sequencer: for the
//! path-conformance and motion-duration rules (issue 25).
//!
//! Modelled: the accepted lines (FIFO `ok`/`error:` replies) of words
//! `letter number`; G0/G1/G2/G3 (I/J and R forms, grbl's full-circle and
//! sign rules), G4 P (s), G20/G21, G90/G91, M3/M4/M5, M2/M30, S, F
//! (clamped to grbl's 1 mm/min), `target …`; the realtime bytes `!`, `~`,
//! 0x18 and the overrides; the sequencer's stops. Lines it does not model
//! (`$J=`, `$H`: the position; `$C`, `laser …`, work offsets G10/G28/
//! G30/G38/G43/G53/G92/G93, patterns, gotos, grids) make it stop judging
//! until the next stop or reset, or forget the position, as noted.

use super::gcode_piece::arc;
pub(super) use super::gcode_piece::{Piece, dist};
use crate::recorder::{EventRecord, SequencerEvent};
use crate::usb_host::Transcript;

/// grbl's `MINIMUM_FEED_RATE`, mm/min.
const MIN_FEED_MM_MIN: f64 = 1.0;

/// Which spot a G-code session moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Spot {
    /// The gimbal's spot (`recording.spot`; the default target).
    Gimbal,
    /// The stepper pan/tilt's spot (`recording.spot`).
    Stepper,
    /// The galvo's (DAC samples).
    Galvo,
    /// The gimbal's and the galvo's (`target both`).
    Both,
}

/// One commanded motion (or lit dwell) of the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Motion {
    /// When its line was sent, µs (it may run from then on: the host
    /// reads the `ok` later).
    pub(super) sent_us: u64,
    /// When its line was accepted (`ok` read by the host), µs.
    pub(super) accepted_us: u64,
    pub(super) piece: Piece,
    /// Lit: G1–G3 (or a G4 after one) with M3/M4 and S > 0 (M4: not a
    /// dwell).
    pub(super) lit: bool,
    /// Time it takes as planned (length / feed, or the dwell), s; `None`
    /// for G0 (the actuator's rapid speed).
    pub(super) planned_s: Option<f64>,
}

/// The G-code between two stops (or resets): its motions and holds.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Session {
    pub(super) spot: Spot,
    /// First accepted motion, µs.
    pub(super) start_us: u64,
    /// The stop, reset or suspension that ended it (`u64::MAX`: none).
    pub(super) end_us: u64,
    pub(super) motions: Vec<Motion>,
    /// Feed holds (`!` … `~`, M0 … `~`), µs; an open one ends at `u64::MAX`.
    pub(super) holds: Vec<(u64, u64)>,
    /// A feed or rapid override was sent: durations are not judged.
    pub(super) overridden: bool,
}

/// The words of a G-code line (`None`: not G-code, e.g. `status`).
fn words(line: &str) -> Option<Vec<(char, f64)>> {
    let mut code = String::new();
    let mut in_paren = false;
    for c in line.chars() {
        match c {
            ';' if !in_paren => break,
            '(' => in_paren = true,
            ')' => in_paren = false,
            c if !in_paren && !c.is_whitespace() => code.push(c.to_ascii_uppercase()),
            _ => {}
        }
    }
    let mut out = Vec::new();
    let mut rest = code.as_str();
    while let Some(letter) = rest.chars().next() {
        if !letter.is_ascii_alphabetic() {
            return None;
        }
        let tail = &rest[1..];
        let end = tail
            .find(|c: char| c.is_ascii_alphabetic())
            .unwrap_or(tail.len());
        out.push((letter, tail[..end].parse::<f64>().ok()?));
        rest = &tail[end..];
    }
    (!out.is_empty()).then_some(out)
}

/// The modal state and what was built so far.
struct Interpreter<'a> {
    motion: u32,
    relative: bool,
    mm_per_unit: f64,
    laser_on: bool,
    dwell_lit: bool,
    power: f64,
    feed: f64,
    /// Where the previous motion ends (`None`: unknown, after a stop).
    at: Option<[f64; 2]>,
    spot: Spot,
    /// Not judging until the next stop (an unmodelled command).
    suspended: bool,
    sessions: Vec<Session>,
    open: Option<Session>,
    spot_at: &'a dyn Fn(Spot, u64) -> Option<[f64; 2]>,
}

impl Interpreter<'_> {
    /// A stop or reset at `t`: the session ends, the position is unknown.
    fn stop(&mut self, t: u64, reset_modes: bool) {
        self.close(t);
        self.at = None;
        self.suspended = false;
        if reset_modes {
            self.motion = 0;
            self.relative = false;
            self.mm_per_unit = 1.0;
            self.laser_on = false;
            self.power = 0.0;
            self.feed = 0.0;
        }
    }

    fn close(&mut self, t: u64) {
        if let Some(mut s) = self.open.take() {
            s.end_us = t;
            for h in s.holds.iter_mut().filter(|h| h.1 == u64::MAX) {
                h.1 = t;
            }
            self.sessions.push(s);
        }
    }

    fn session(&mut self, t: u64) -> &mut Session {
        let spot = self.spot;
        self.open.get_or_insert_with(|| Session {
            spot,
            start_us: t,
            end_us: u64::MAX,
            motions: Vec::new(),
            holds: Vec::new(),
            overridden: false,
        })
    }

    fn hold(&mut self, t: u64) {
        if let Some(s) = self.open.as_mut()
            && s.holds.last().is_none_or(|h| h.1 != u64::MAX)
        {
            s.holds.push((t, u64::MAX));
        }
    }

    fn resume(&mut self, t: u64) {
        if let Some(h) = self.open.as_mut().and_then(|s| s.holds.last_mut())
            && h.1 == u64::MAX
        {
            h.1 = t;
        }
    }

    /// An accepted non-G-code line.
    fn command(&mut self, t: u64, line: &str) {
        let line = line.trim().to_ascii_lowercase();
        let first = line.split_ascii_whitespace().next().unwrap_or("");
        match first {
            "target" => {
                self.stop(t, false);
                self.spot = match line.split_ascii_whitespace().nth(1) {
                    Some("galvo") => Spot::Galvo,
                    Some("both") => Spot::Both,
                    Some("stepper") => Spot::Stepper,
                    _ => Spot::Gimbal,
                };
            }
            _ if line.starts_with("$j=") || line.starts_with("$h") => self.at = None,
            "pattern" | "goto" | "grid" | "laser" | "$c" | "home" => {
                self.close(t);
                self.suspended = true;
            }
            _ => {}
        }
    }

    /// An accepted G-code line, sent at `sent`.
    fn gcode(&mut self, sent: u64, t: u64, words: &[(char, f64)]) {
        let (mut x, mut y, mut i, mut j, mut r, mut p) = (None, None, None, None, None, None);
        let mut dwell = false;
        for &(letter, v) in words {
            match (letter, v) {
                ('G', 0.0) | ('G', 1.0) | ('G', 2.0) | ('G', 3.0) => self.motion = v as u32,
                ('G', 4.0) => dwell = true,
                ('G', 20.0) => self.mm_per_unit = 25.4,
                ('G', 21.0) => self.mm_per_unit = 1.0,
                ('G', 90.0) => self.relative = false,
                ('G', 91.0) => self.relative = true,
                ('G', 10.0 | 28.0 | 30.0 | 38.2 | 43.1 | 53.0 | 92.0 | 93.0) => {
                    self.close(t);
                    self.suspended = true;
                    return;
                }
                ('M', 3.0 | 4.0) => {
                    self.laser_on = true;
                    self.dwell_lit = v == 3.0;
                }
                ('M', 5.0 | 2.0 | 30.0) => self.laser_on = false,
                ('M', 0.0 | 1.0) => self.hold(t),
                ('S', v) => self.power = v,
                ('F', v) => self.feed = v * self.mm_per_unit,
                ('X', v) => x = Some(v * self.mm_per_unit),
                ('Y', v) => y = Some(v * self.mm_per_unit),
                ('I', v) => i = Some(v * self.mm_per_unit),
                ('J', v) => j = Some(v * self.mm_per_unit),
                ('R', v) => r = Some(v * self.mm_per_unit),
                ('P', v) => p = Some(v),
                _ => {}
            }
        }
        let lit_mode = self.laser_on && self.power > 0.0 && (1..=3).contains(&self.motion);
        if dwell {
            let here = self.at.or_else(|| (self.spot_at)(self.spot, t));
            let (Some(at), Some(s)) = (here, p) else {
                return;
            };
            let lit = lit_mode && self.dwell_lit;
            self.push(sent, t, Piece::Point(at), lit, Some(s));
            return;
        }
        if x.is_none() && y.is_none() {
            return;
        }
        let Some(from) = self.at.or_else(|| (self.spot_at)(self.spot, t)) else {
            // No sample yet to start from: the path is unknown, its end
            // too unless absolute on both axes.
            self.at = x.zip(y).filter(|_| !self.relative).map(|(x, y)| [x, y]);
            return;
        };
        let axis = |v: Option<f64>, k: usize| match v {
            Some(v) if self.relative => from[k] + v,
            Some(v) => v,
            None => from[k],
        };
        let to = [axis(x, 0), axis(y, 1)];
        self.at = Some(to);
        let piece = match self.motion {
            2 | 3 => match arc(from, to, i, j, r, self.motion == 2) {
                Some(piece) => piece,
                None => return,
            },
            _ => Piece::Line { a: from, b: to },
        };
        let planned_s =
            (self.motion != 0).then(|| piece.length_mm() / (self.feed.max(MIN_FEED_MM_MIN) / 60.0));
        if self.motion == 0 || piece.length_mm() > 0.0 {
            self.push(sent, t, piece, lit_mode, planned_s);
        }
    }

    fn push(&mut self, sent: u64, t: u64, piece: Piece, lit: bool, planned_s: Option<f64>) {
        if self.suspended {
            return;
        }
        self.session(sent).motions.push(Motion {
            sent_us: sent,
            accepted_us: t,
            piece,
            lit,
            planned_s,
        });
    }
}

/// The G-code sessions of a run, from its transcript and the sequencer's
/// stops; `spot_at(spot, t)` gives where a spot was at `t` (µs, mm), for
/// the start of the first motion after a stop.
pub(super) fn sessions(
    transcript: &Transcript,
    events: &[EventRecord],
    spot_at: &dyn Fn(Spot, u64) -> Option<[f64; 2]>,
) -> Vec<Session> {
    let mut it = Interpreter {
        motion: 0,
        relative: false,
        mm_per_unit: 1.0,
        laser_on: false,
        dwell_lit: false,
        power: 0.0,
        feed: 0.0,
        at: None,
        spot: Spot::Gimbal,
        suspended: false,
        sessions: Vec::new(),
        open: None,
        spot_at,
    };
    let stops: Vec<u64> = events
        .iter()
        .filter_map(|e| match &e.event {
            SequencerEvent::Stopped { why }
                if why != "pattern complete" && why != "G-code started" =>
            {
                Some(e.t_us)
            }
            _ => None,
        })
        .collect();
    let mut next_stop = 0;
    let mut pending: std::collections::VecDeque<(u64, &str)> = Default::default();
    for (t, line) in &transcript.lines {
        let t = *t;
        while next_stop < stops.len() && stops[next_stop] <= t {
            it.stop(stops[next_stop], false);
            next_stop += 1;
        }
        if let Some(sent) = line.strip_prefix("> ") {
            pending.push_back((t, sent));
        } else if let Some(byte) = line.strip_prefix(">> 0x") {
            match u8::from_str_radix(byte, 16).unwrap_or(0) {
                0x18 => {
                    pending.clear();
                    it.stop(t, true);
                }
                b'!' | 0x84 => it.hold(t),
                b'~' => it.resume(t),
                0x90..=0x9d => {
                    if let Some(s) = it.open.as_mut() {
                        s.overridden = true;
                    }
                }
                _ => {}
            }
        } else if line == "ok" || line.starts_with("error:") {
            let Some((sent_us, sent)) = pending.pop_front() else {
                continue;
            };
            if line != "ok" {
                continue;
            }
            match words(sent) {
                Some(w) => it.gcode(sent_us, t, &w),
                None => it.command(t, sent),
            }
        }
    }
    it.close(u64::MAX);
    it.sessions
}

#[cfg(test)]
mod tests;
