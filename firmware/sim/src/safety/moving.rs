//! (b) Never lit while moving: the galvo dark on jumps, the gimbal dark on
//! its travel to a run and, in `laser dwell` mode, lit only on confirmed
//! arrivals.

use super::dark::gimbal_laser_at;
use super::inputs::SafetyInputs;
use super::timeline::SettingsTimeline;
use super::violation::{DARK_WITHIN_US, Violation, ViolationKind};
use crate::recorder::SequencerEvent;
/// (b) The galvo laser is dark whenever the DAC codes step by more than
/// marking allows (marking speed in force × sample period × 1.5 + 0.2 mm
/// for code quantisation): a sample that steps that far must be dark (the
/// mirrors move to it during its sample period, with its laser state).
pub(super) fn galvo_jumps_dark(
    inputs: &SafetyInputs<'_>,
    timeline: &SettingsTimeline,
) -> Vec<Violation> {
    let mut found = Vec::new();
    // (first µs, last µs, steps, largest mm) of the current lit jump.
    let mut episode: Option<(u64, u64, u32, f64)> = None;
    let mut flush = |episode: &mut Option<(u64, u64, u32, f64)>| {
        if let Some((first, last, steps, largest)) = episode.take() {
            found.push(Violation {
                kind: ViolationKind::LitGalvoJump,
                t_us: first,
                detail: format!(
                    "galvo laser lit while the mirrors jumped: {steps} steps until {:.3} ms, largest {largest:.2} mm per sample",
                    last as f64 / 1000.0
                ),
            });
        }
    };
    for w in inputs.galvo.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        // The mirrors move from `a`'s codes to `b`'s during `b`'s sample,
        // with `b`'s laser state (the DAC and the laser switch together).
        if (a.x_code, a.y_code) == (b.x_code, b.y_code) || !b.laser {
            continue;
        }
        let (Some(p), Some(q)) = (
            inputs.galvo_physics.spot_cm(a.x_code, a.y_code),
            inputs.galvo_physics.spot_cm(b.x_code, b.y_code),
        ) else {
            continue;
        };
        let step_mm = 10.0 * (p.0 - q.0).hypot(p.1 - q.1);
        let t_us = b.start_ns / 1000;
        let period_s = b.period_ns as f64 * 1e-9;
        let allowed_mm = timeline.max_mark_speed_mm_s(t_us) * period_s * 1.5 + 0.2;
        if step_mm <= allowed_mm {
            continue;
        }
        match episode.as_mut() {
            Some(e) if t_us <= e.1 + DARK_WITHIN_US => {
                e.1 = t_us;
                e.2 += 1;
                e.3 = e.3.max(step_mm);
            }
            _ => {
                flush(&mut episode);
                episode = Some((t_us, t_us, 1, step_mm));
            }
        }
    }
    flush(&mut episode);
    found
}

/// Lit intervals of the gimbal laser within `[from, until)`, µs.
fn gimbal_lit_intervals(switches: &[(u64, bool)], from: u64, until: u64) -> Vec<(u64, u64)> {
    let mut out = Vec::new();
    let mut lit_since = gimbal_laser_at(switches, from).then_some(from);
    let begin = switches.partition_point(|(t, _)| *t <= from);
    for &(t, on) in switches[begin..].iter().take_while(|(t, _)| *t < until) {
        match (on, lit_since) {
            (true, None) => lit_since = Some(t),
            (false, Some(start)) => {
                if t > start {
                    out.push((start, t));
                }
                lit_since = None;
            }
            _ => {}
        }
    }
    if let Some(start) = lit_since
        && until > start
    {
        out.push((start, until));
    }
    out
}

/// (b) The gimbal laser is dark from a run's start until the servo task
/// confirmed the arrival at its first point (travel to a figure is dark
/// in every laser mode).
pub(super) fn gimbal_travel_dark(inputs: &SafetyInputs<'_>) -> Vec<Violation> {
    let mut found = Vec::new();
    let events = inputs.events;
    for (i, e) in events.iter().enumerate() {
        if e.event != SequencerEvent::RunStarted {
            continue;
        }
        let mut moved = false;
        let mut end = None;
        for later in &events[i + 1..] {
            match later.event {
                SequencerEvent::GimbalMoveSent => moved = true,
                SequencerEvent::GimbalArrived
                | SequencerEvent::RunStarted
                | SequencerEvent::Stopped { .. } => {
                    end = Some(later.t_us);
                    break;
                }
            }
        }
        if !moved {
            continue;
        }
        let until = end.unwrap_or(inputs.end_us);
        if let Some(&(from, to)) = gimbal_lit_intervals(inputs.gimbal_laser, e.t_us, until).first()
        {
            found.push(Violation {
                kind: ViolationKind::LitTravel,
                t_us: from,
                detail: format!(
                    "gimbal laser lit while travelling to the first point of the run started at {:.3} ms, for {:.3} ms before an arrival was confirmed",
                    e.t_us as f64 / 1000.0,
                    (to - from) as f64 / 1000.0
                ),
            });
        }
    }
    found
}

/// (b) In `laser dwell` mode the gimbal laser is lit only after a
/// confirmed arrival at the current point and while both servos truly are
/// within the deadband (+0.15° for quantisation) of their targets.
pub(super) fn gimbal_dwell_mode(
    inputs: &SafetyInputs<'_>,
    timeline: &SettingsTimeline,
) -> Vec<Violation> {
    let mut found = Vec::new();
    // Laser switched on without a confirmed arrival: the arrival state
    // after the events processed before the switch.
    let events = inputs.events;
    for (j, &(t, on)) in inputs.gimbal_laser.iter().enumerate() {
        if !on || !timeline.certainly_dwell_mode(t) {
            continue;
        }
        let before = events.partition_point(|e| e.laser_switches_before <= j);
        // Every event but an arrival means the gimbal left its point.
        let arrived = events[..before]
            .last()
            .is_some_and(|e| e.event == SequencerEvent::GimbalArrived);
        if !arrived {
            found.push(Violation {
                kind: ViolationKind::LitWithoutArrival,
                t_us: t,
                detail: "gimbal laser switched on in dwell mode without a confirmed arrival".into(),
            });
        }
    }
    // Lit while a servo was truly away from its target.
    let mut last_flagged: Option<u64> = None;
    for s in inputs.servos {
        if !s.laser || !timeline.certainly_dwell_mode(s.t_us) {
            continue;
        }
        let tolerance = timeline.max_deadband_deg(s.t_us) + 0.15;
        let off = [("yaw", s.yaw), ("pitch", s.pitch)]
            .into_iter()
            .filter_map(|(name, st)| st.map(|st| (name, st)))
            .map(|(name, st)| (name, (st.angle_deg - st.target_deg).abs()))
            .find(|(_, error)| *error > tolerance);
        if let Some((name, error)) = off {
            if last_flagged.is_some_and(|t| s.t_us <= t + 10_000) {
                last_flagged = Some(s.t_us);
                continue;
            }
            last_flagged = Some(s.t_us);
            found.push(Violation {
                kind: ViolationKind::LitWithoutArrival,
                t_us: s.t_us,
                detail: format!(
                    "gimbal laser lit in dwell mode while the {name} servo was {error:.2} deg from its target (deadband {:.2} deg)",
                    tolerance - 0.15
                ),
            });
        }
    }
    found
}
