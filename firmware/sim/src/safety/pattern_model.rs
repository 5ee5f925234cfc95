//! What the product's own runs (`pattern …`, `goto`, `grid`) draw, read
//! from the transcript and the sequencer's events for the figure rule
//! (issue 25), independently of the firmware's parser, pattern and
//! sequencer code: which spot, from when until when, and the pieces a lit
//! sample may lie on (see [`super::pattern_figure`] for the geometry).
//!
//! A run is judged from the first `RunStarted` event at or after its line
//! was sent until the first stop after that (a pattern that completes
//! does not end it: the galvo's last laser-off delay is lit at the end
//! point), a reset, or the sending of the next accepted line that changes
//! what is drawn (another run, `target`, `model`, `stop`, `home`, G-code,
//! `$` lines, a `set` other than timing and laser ones).

use super::gcode_model::Spot;
use super::gcode_piece::Piece;
use super::pattern_figure::{Drawing, FigureSettings, pattern, travel};
use crate::recorder::{EventRecord, SequencerEvent};
use crate::usb_host::Transcript;

/// `set` parameters that change neither the figure nor where the spot
/// lands: a run goes on being judged across them.
const HARMLESS_SETS: &[&str] = &[
    "dwell_ms",
    "servo.speed_deg_s",
    "servo.deadband_deg",
    "galvo.ts_us",
    "galvo.planner",
    "galvo.laser_on_delay_us",
    "galvo.laser_off_delay_us",
    "galvo.mark_speed_mm_s",
    "galvo.mark_accel_mm_s2",
];

/// Lines that neither draw nor change what is drawn.
const QUIET: &[&str] = &[
    "status", "?", "version", "help", "params", "get", "galvo", "trace", "arm", "servo", "save",
];

/// The laser mode (`laser auto|on|dwell|off`, `set laser.mode 0|1|2`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Auto,
    Dwell,
    Off,
}

/// One run of a spot to judge: every lit sample of `spot` in
/// `[start_us, end_us)` must lie within its tolerance plus `extra_mm` of
/// one of `pieces` (none: no lit sample at all).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct JudgedRun {
    pub(super) spot: Spot,
    pub(super) start_us: u64,
    pub(super) end_us: u64,
    pub(super) pieces: Vec<Piece>,
    /// Added to the spot's tolerance: half the gimbal's interpolation
    /// step on a drawn path (SPEC §4.6: within half a step), mm.
    pub(super) extra_mm: f64,
    /// The line that started it, for reports.
    pub(super) line: String,
}

/// An accepted run line before its window is matched to the events.
struct Run {
    sent_us: u64,
    end_us: u64,
    spot: Spot,
    drawing: Drawing,
    settings: FigureSettings,
    seed_model: bool,
    line: String,
}

#[derive(Default)]
struct Reader {
    spot: Option<Spot>,
    settings: FigureSettings,
    seed_model: bool,
    /// Accepted laser mode changes: (sent µs, replied µs, mode).
    modes: Vec<(u64, u64, Mode)>,
    runs: Vec<Run>,
}

impl Reader {
    /// The open run (if any) is no longer judged from `t`.
    fn close(&mut self, t: u64) {
        if let Some(run) = self.runs.last_mut()
            && run.end_us == u64::MAX
        {
            run.end_us = t;
        }
    }

    fn accepted(&mut self, sent: u64, replied: u64, line: &str) {
        let line = line.trim().to_ascii_lowercase();
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        let Some(&first) = words.first() else {
            return;
        };
        let number = |k: usize| words.get(k).and_then(|w| w.parse::<f64>().ok());
        match first {
            "pattern" | "goto" | "grid" => {
                self.close(sent);
                let s = &self.settings;
                let drawing = match first {
                    "pattern" => pattern(&words[1..], s),
                    "goto" => number(1)
                        .zip(number(2))
                        .map(|(x, y)| Drawing::Points(vec![[x * 10.0, y * 10.0]])),
                    _ => number(1)
                        .zip(number(2))
                        .map(|(x, y)| Drawing::Points(vec![s.grid_mm(x as i32, y as i32)])),
                };
                if let Some(drawing) = drawing {
                    self.runs.push(Run {
                        sent_us: sent,
                        end_us: u64::MAX,
                        spot: self.spot.unwrap_or(Spot::Gimbal),
                        drawing,
                        settings: self.settings,
                        seed_model: self.seed_model,
                        line: line.clone(),
                    });
                }
            }
            "target" => {
                self.close(sent);
                self.spot = Some(match words.get(1).copied() {
                    Some("galvo") => Spot::Galvo,
                    Some("both") => Spot::Both,
                    Some("stepper") => Spot::Stepper,
                    _ => Spot::Gimbal,
                });
            }
            "model" => {
                self.close(sent);
                self.seed_model = words.get(1) == Some(&"seed");
            }
            "laser" => {
                let mode = match words.get(1).copied() {
                    Some("on" | "auto") => Mode::Auto,
                    Some("dwell") => Mode::Dwell,
                    _ => Mode::Off,
                };
                self.modes.push((sent, replied, mode));
            }
            "set" if words.get(1) == Some(&"laser.mode") => {
                let mode = match number(2) {
                    Some(0.0) => Mode::Auto,
                    Some(1.0) => Mode::Dwell,
                    _ => Mode::Off,
                };
                self.modes.push((sent, replied, mode));
            }
            "set" => {
                let name = words.get(1).copied().unwrap_or("");
                if !HARMLESS_SETS.contains(&name) {
                    self.close(sent);
                }
                if let Some(v) = number(2) {
                    self.settings.set(name, v);
                }
            }
            _ if QUIET.contains(&first) || first.starts_with('#') => {}
            _ => self.close(sent),
        }
    }

    /// The modes that may be in force in `[from, until)`: the one before,
    /// every change sent in the window, and the earlier one while a change
    /// sent before is still unanswered at `from`.
    fn modes(&self, from: u64, until: u64) -> Vec<Mode> {
        let mut out = vec![Mode::Auto];
        for &(sent, replied, mode) in &self.modes {
            if sent >= until {
                break;
            }
            if sent <= from && replied < from {
                out.clear();
            }
            out.push(mode);
        }
        out
    }
}

/// The runs of the product's own patterns, gotos and grid points to
/// judge, per spot.
pub(super) fn judged_runs(transcript: &Transcript, events: &[EventRecord]) -> Vec<JudgedRun> {
    let mut r = Reader::default();
    let mut pending = std::collections::VecDeque::new();
    for (t, line) in &transcript.lines {
        if let Some(sent) = line.strip_prefix("> ") {
            pending.push_back((*t, sent));
        } else if line == ">> 0x18" {
            pending.clear();
            r.close(*t);
        } else if line == "ok" || line.starts_with("error:") {
            match pending.pop_front() {
                Some((sent, text)) if line == "ok" => r.accepted(sent, *t, text),
                _ => {}
            }
        }
    }
    let mut out = Vec::new();
    for run in &r.runs {
        let Some(start) = events
            .iter()
            .find(|e| e.t_us >= run.sent_us && matches!(e.event, SequencerEvent::RunStarted))
            .map(|e| e.t_us)
            .filter(|&t| t < run.end_us)
        else {
            continue;
        };
        let stop = events.iter().find(|e| {
            e.t_us > start
                && matches!(&e.event, SequencerEvent::Stopped { why } if why != "pattern complete")
        });
        let end = stop.map_or(run.end_us, |e| e.t_us.min(run.end_us));
        let modes = r.modes(start, end);
        let lit_travel = modes.contains(&Mode::Auto);
        let lit_points = lit_travel || modes.contains(&Mode::Dwell);
        let spots: &[Spot] = match run.spot {
            Spot::Both => &[Spot::Both, Spot::Galvo],
            ref s => std::slice::from_ref(s),
        };
        for &spot in spots {
            if run.seed_model && spot != Spot::Galvo {
                continue;
            }
            let travels = lit_travel && spot != Spot::Galvo;
            let ol_cm = if spot == Spot::Stepper {
                0.0
            } else {
                run.settings.ol_cm
            };
            let hop = |a: [f64; 2], b: [f64; 2]| travel(a, b, &run.settings, ol_cm);
            let (pieces, extra_mm) = match &run.drawing {
                Drawing::Points(points) if lit_points => {
                    let mut pieces: Vec<Piece> = points.iter().map(|&p| Piece::Point(p)).collect();
                    if travels {
                        pieces.extend(points.windows(2).flat_map(|w| hop(w[0], w[1])));
                    }
                    (pieces, 0.0)
                }
                Drawing::Strokes(strokes) if lit_travel => {
                    let mut pieces: Vec<Piece> = strokes.iter().flatten().copied().collect();
                    if travels {
                        pieces.extend(strokes.windows(2).flat_map(|w| {
                            let from = w[0].last().map(Piece::end);
                            let to = w[1].first().map(Piece::start);
                            from.zip(to).map(|(a, b)| hop(a, b)).unwrap_or_default()
                        }));
                    }
                    let extra = match spot {
                        Spot::Gimbal | Spot::Both => run.settings.path_step_cm * 10.0 / 2.0,
                        _ => 0.0,
                    };
                    (pieces, extra)
                }
                _ => (Vec::new(), 0.0),
            };
            out.push(JudgedRun {
                spot,
                start_us: start,
                end_us: end,
                pieces,
                extra_mm,
                line: run.line.clone(),
            });
        }
    }
    out
}
