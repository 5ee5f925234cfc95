//! (e) Path conformance and (f) motion duration of G-code (issue 25):
//! judged against the toolpath [`super::gcode_model`] interprets from the
//! transcript, independently of the firmware.
//!
//! * **(e)** every lit sample of the spot a G-code session moves lies
//!   within [`Spot::tolerance_mm`] of a lit piece accepted by then
//!   (G1–G3 with the laser on and S > 0, a lit G4 at its point).
//! * **(f)** every motion ends within its bound: the spot is at its end
//!   (within the tolerance) by `start + planned × 1.1 +`
//!   [`DURATION_SLACK_S`] (G0: length at [`RAPID_MIN_MM_S`]), its start
//!   being its acceptance or the previous motion's deadline, feed holds
//!   added; and when nothing follows it, no lit sample leaves its end
//!   after that deadline. Sessions with feed or rapid overrides are not
//!   timed.

use super::gcode_model::{Motion, Session, Spot, dist, sessions};
use super::inputs::SafetyInputs;
use super::violation::{Violation, ViolationKind};

/// Slack of a motion's duration bound for acceleration, a servo's
/// arrival and the laser's switching, s.
pub const DURATION_SLACK_S: f64 = 0.5;
/// Slowest rapid (G0) any actuator makes, mm/s.
pub const RAPID_MIN_MM_S: f64 = 20.0;

impl Spot {
    /// How far a lit sample may lie from the commanded path, mm: the
    /// stepper's cutting tolerance (0.05 mm) and half a microstep per
    /// axis (≤ 0.35 mm near the board's middle) → 0.6 mm; the gimbal's
    /// servos (0.1° commands, tracking lag between path steps) → 2 mm;
    /// the galvo's DAC code (~0.085 mm) and laser delays → 0.3 mm.
    pub(super) fn tolerance_mm(self) -> f64 {
        match self {
            Spot::Stepper => 0.6,
            Spot::Gimbal | Spot::Both => 2.0,
            Spot::Galvo => 0.3,
        }
    }
}

/// One spot's samples: (t µs, board mm, lit), in time order.
pub(super) type Samples = Vec<(u64, [f64; 2], bool)>;

/// The pointing actuator's (gimbal/stepper) and the galvo's samples.
pub(super) fn samples(inputs: &SafetyInputs<'_>) -> (Samples, Samples) {
    let pointing = inputs
        .spot
        .iter()
        .map(|s| (s.t_us, [s.x_cm * 10.0, s.y_cm * 10.0], s.laser))
        .collect();
    let galvo = inputs
        .galvo
        .iter()
        .filter_map(|s| {
            let (x, y) = inputs.galvo_physics.spot_cm(s.x_code, s.y_code)?;
            Some((s.start_ns / 1000, [x * 10.0, y * 10.0], s.laser))
        })
        .collect();
    (pointing, galvo)
}

/// The samples of `spot` in `[from, until)`.
pub(super) fn window(samples: &Samples, from: u64, until: u64) -> &[(u64, [f64; 2], bool)] {
    let a = samples.partition_point(|s| s.0 < from);
    let b = samples.partition_point(|s| s.0 < until);
    &samples[a..b.max(a)]
}

/// (e) and (f) on every G-code session of the run.
pub(super) fn gcode_conformance(inputs: &SafetyInputs<'_>) -> (Vec<Violation>, Vec<Violation>) {
    let (pointing, galvo) = samples(inputs);
    let of = |spot: Spot| {
        if spot == Spot::Galvo {
            &galvo
        } else {
            &pointing
        }
    };
    let spot_at = |spot: Spot, t: u64| {
        let s = of(spot);
        let k = s.partition_point(|x| x.0 <= t);
        k.checked_sub(1).map(|k| s[k].1)
    };
    let sessions = sessions(inputs.transcript, inputs.events, &spot_at);
    let mut path = Vec::new();
    let mut duration = Vec::new();
    for session in &sessions {
        let end = session.end_us.min(inputs.end_us);
        let spots: &[Spot] = match session.spot {
            Spot::Both => &[Spot::Both, Spot::Galvo],
            _ => std::slice::from_ref(&session.spot),
        };
        for &spot in spots {
            let samples = window(of(spot), session.start_us, end);
            path.extend(off_path(session, spot, samples));
            if !session.overridden {
                duration.extend(late(session, spot, of(spot), end));
            }
        }
    }
    (path, duration)
}

/// (e) Lit samples farther than the tolerance from every lit piece
/// accepted by their time, as episodes.
fn off_path(session: &Session, spot: Spot, samples: &[(u64, [f64; 2], bool)]) -> Vec<Violation> {
    let tol = spot.tolerance_mm();
    let lit: Vec<&Motion> = session.motions.iter().filter(|m| m.lit).collect();
    let mut found = Vec::new();
    // (first µs, last µs, samples, worst mm, where).
    let mut episode: Option<OffEpisode> = None;
    let mut cursor = 0usize;
    for &(t, p, _) in samples.iter().filter(|s| s.2) {
        let known = lit.partition_point(|m| m.sent_us <= t);
        let near = |k: usize| lit[k].piece.distance_mm(p);
        let nearest = (cursor..known.min(cursor + 4))
            .find(|&k| near(k) <= tol)
            .map(|k| (k, near(k)))
            .or_else(|| {
                (0..known)
                    .map(|k| (k, near(k)))
                    .min_by(|a, b| a.1.total_cmp(&b.1))
            });
        match nearest {
            Some((k, d)) if d <= tol => {
                cursor = k;
                continue;
            }
            _ => {}
        }
        let d = nearest.map_or(f64::INFINITY, |n| n.1);
        if let Some(done) = extend_episode(&mut episode, (t, d, p), 100_000) {
            flush_path(&mut found, Some(done), tol, spot);
        }
    }
    flush_path(&mut found, episode, tol, spot);
    found
}

/// Lit samples off their path close together in time: first and last
/// sample (µs), how many, the worst distance (mm) and where it was (mm).
pub(super) type OffEpisode = (u64, u64, u32, f64, [f64; 2]);

/// Adds the off-path sample `(t_us, distance_mm, point_mm)` to `episode`
/// when it comes within `gap_us` of its last sample; otherwise starts a
/// new episode with it and returns the one it ends.
pub(super) fn extend_episode(
    episode: &mut Option<OffEpisode>,
    (t, d, p): (u64, f64, [f64; 2]),
    gap_us: u64,
) -> Option<OffEpisode> {
    match episode.as_mut() {
        Some(e) if t <= e.1 + gap_us => {
            e.1 = t;
            e.2 += 1;
            if d > e.3 {
                e.3 = d;
                e.4 = p;
            }
            None
        }
        _ => episode.replace((t, t, 1, d, p)),
    }
}

fn flush_path(found: &mut Vec<Violation>, episode: Option<OffEpisode>, tol: f64, spot: Spot) {
    if let Some((first, last, n, worst, p)) = episode {
        found.push(Violation {
            kind: ViolationKind::OffPath,
            t_us: first,
            detail: format!(
                "{spot:?} spot lit off the G-code path: {n} samples until {:.3} ms, worst {worst:.2} mm (tolerance {tol} mm) at ({:.2}, {:.2}) mm",
                last as f64 / 1000.0,
                p[0],
                p[1]
            ),
        });
    }
}

/// The deadline of a motion that may start at `start` (µs), holds added.
fn deadline(m: &Motion, start: u64, holds: &[(u64, u64)]) -> u64 {
    let s = match m.planned_s {
        Some(s) => s * 1.1,
        None => m.piece.length_mm() / RAPID_MIN_MM_S,
    };
    let mut d = start.saturating_add(((s + DURATION_SLACK_S) * 1e6) as u64);
    for &(h0, h1) in holds {
        if h0 < d && h1 > start {
            d = d.saturating_add(h1.saturating_sub(h0.max(start)));
        }
    }
    d
}

/// (f) Motions not at their end by their deadline, and lit samples that
/// leave the end of the last motion after its deadline.
fn late(session: &Session, spot: Spot, samples: &Samples, end: u64) -> Vec<Violation> {
    let tol = spot.tolerance_mm();
    let mut found = Vec::new();
    let mut previous = 0u64;
    for (k, m) in session.motions.iter().enumerate() {
        let start = m.accepted_us.max(previous);
        let d = deadline(m, start, &session.holds);
        if d >= end {
            break;
        }
        previous = d;
        let to = m.piece.end();
        let arrived = window(samples, m.sent_us, d.saturating_add(1))
            .iter()
            .any(|s| dist(s.1, to) <= tol);
        if !arrived {
            // The closest it came before the next stop, for the report.
            let closest = window(samples, m.sent_us, end)
                .iter()
                .map(|s| (dist(s.1, to), s.0))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .unwrap_or((f64::INFINITY, 0));
            found.push(Violation {
                kind: ViolationKind::LateMotion,
                t_us: d,
                detail: format!(
                    "{spot:?} spot not at ({:.2}, {:.2}) mm by {:.3} ms, the end of its motion's bound ({:.3} s planned; closest {:.2} mm at {:.3} ms)",
                    to[0],
                    to[1],
                    d as f64 / 1000.0,
                    m.planned_s.unwrap_or(0.0),
                    closest.0,
                    closest.1 as f64 / 1000.0
                ),
            });
            break;
        }
        let next = session
            .motions
            .get(k + 1)
            .map_or(end, |n| n.accepted_us.min(end));
        let strays = window(samples, d, next)
            .iter()
            .find(|s| s.2 && dist(s.1, to) > tol);
        if let Some(&(t, p, _)) = strays {
            found.push(Violation {
                kind: ViolationKind::LateMotion,
                t_us: t,
                detail: format!(
                    "{spot:?} spot lit at ({:.2}, {:.2}) mm, {:.2} mm from the end of the last motion, after its bound ({:.3} ms)",
                    p[0],
                    p[1],
                    dist(p, to),
                    d as f64 / 1000.0
                ),
            });
            break;
        }
    }
    found
}

#[cfg(test)]
mod tests;
