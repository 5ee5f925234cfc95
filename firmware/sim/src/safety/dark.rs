//! (a) Dark after a stop: every laser dark from 1 ms after a shutdown until
//! the next start.

use super::inputs::SafetyInputs;
use super::violation::{DARK_WITHIN_US, STOPS_THAT_ARE_NOT_SHUTDOWNS, Violation, ViolationKind};
use crate::recorder::SequencerEvent;
/// Something after which every laser must go dark.
#[derive(Debug, Clone)]
struct Shutdown {
    t_us: u64,
    why: String,
}

/// Windows in which every laser must be dark: from 1 ms after the first
/// shutdown since the last run start until the next start. Galvo samples
/// computed before that next start stay under the rule even when output
/// later. `(shutdown, next start µs or None)`.
fn dark_windows(inputs: &SafetyInputs<'_>) -> Vec<(Shutdown, Option<u64>)> {
    // Sequencer events in processing order, underruns (from the galvo
    // loop) placed before the events at or after their time.
    let mut underruns = inputs.underruns_ns.iter().map(|ns| ns / 1000).peekable();
    let mut windows = Vec::new();
    let mut first: Option<Shutdown> = None;
    for event in inputs.events {
        while let Some(t_us) = underruns.next_if(|t| *t <= event.t_us) {
            first.get_or_insert(Shutdown {
                t_us,
                why: "galvo underrun (detected by the loop)".into(),
            });
        }
        match &event.event {
            SequencerEvent::Stopped { why }
                if !STOPS_THAT_ARE_NOT_SHUTDOWNS.contains(&why.as_str()) =>
            {
                first.get_or_insert(Shutdown {
                    t_us: event.t_us,
                    why: why.clone(),
                });
            }
            SequencerEvent::RunStarted => {
                if let Some(shutdown) = first.take() {
                    windows.push((shutdown, Some(event.t_us)));
                }
            }
            _ => {}
        }
    }
    for t_us in underruns {
        first.get_or_insert(Shutdown {
            t_us,
            why: "galvo underrun (detected by the loop)".into(),
        });
    }
    if let Some(shutdown) = first {
        windows.push((shutdown, None));
    }
    windows
}

/// (a) Every laser dark from 1 ms after a shutdown until the next start.
pub(super) fn dark_after_stops(inputs: &SafetyInputs<'_>) -> Vec<Violation> {
    let windows = dark_windows(inputs);
    let mut found = Vec::new();
    // Galvo: each window scans the stretches up to the next window's start
    // (a later window's rule includes this one's).
    let galvo = &inputs.galvo;
    for (i, (shutdown, next_start)) in windows.iter().enumerate() {
        let from_ns = (shutdown.t_us + DARK_WITHIN_US) * 1000;
        let until_ns = windows
            .get(i + 1)
            .map_or(u64::MAX, |(s, _)| (s.t_us + DARK_WITHIN_US) * 1000);
        let computed_before_ns = next_start.map_or(u64::MAX, |t| t * 1000);
        // A later window starting as early includes this one's rule.
        if from_ns >= until_ns {
            continue;
        }
        let begin = galvo.partition_point(|s| s.last_ns() < from_ns);
        let mut lit: Option<(u64, u64, u64)> = None; // first ns, last ns, samples
        for s in galvo[begin..].iter().take_while(|s| s.start_ns < until_ns) {
            if !s.laser || s.computed_ns >= computed_before_ns {
                continue;
            }
            // Samples output in [from_ns, until_ns).
            let skip = from_ns.saturating_sub(s.start_ns).div_ceil(s.period_ns);
            let end = until_ns
                .saturating_sub(s.start_ns)
                .div_ceil(s.period_ns)
                .min(s.count);
            if skip >= end {
                continue;
            }
            let first_ns = s.start_ns + skip * s.period_ns;
            let entry = lit.get_or_insert((first_ns, first_ns, 0));
            entry.1 = s.start_ns + (end - 1) * s.period_ns;
            entry.2 += end - skip;
        }
        if let Some((first_ns, last_ns, samples)) = lit {
            found.push(Violation {
                kind: ViolationKind::LitAfterStop,
                t_us: first_ns / 1000,
                detail: format!(
                    "galvo laser lit {:.3} ms after {} (processed at {:.3} ms): {samples} lit samples until {:.3} ms",
                    (first_ns as f64 / 1000.0 - shutdown.t_us as f64) / 1000.0,
                    shutdown.why,
                    shutdown.t_us as f64 / 1000.0,
                    last_ns as f64 / 1e6,
                ),
            });
        }
        // Gimbal: off from 1 ms after the shutdown until the next start.
        let from_us = shutdown.t_us + DARK_WITHIN_US;
        let until_us = next_start.unwrap_or(u64::MAX);
        if from_us >= until_us {
            continue;
        }
        let on_at_start = gimbal_laser_at(inputs.gimbal_laser, from_us);
        let switched_on = inputs
            .gimbal_laser
            .iter()
            .find(|(t, on)| *on && *t > from_us && *t < until_us)
            .map(|(t, _)| *t);
        if let Some(t_us) = on_at_start.then_some(from_us).or(switched_on) {
            found.push(Violation {
                kind: ViolationKind::LitAfterStop,
                t_us,
                detail: format!(
                    "gimbal laser lit {:.3} ms after {} (processed at {:.3} ms)",
                    (t_us - shutdown.t_us) as f64 / 1000.0,
                    shutdown.why,
                    shutdown.t_us as f64 / 1000.0
                ),
            });
        }
    }
    found
}

pub(super) fn gimbal_laser_at(switches: &[(u64, bool)], t_us: u64) -> bool {
    let n = switches.partition_point(|(t, _)| *t <= t_us);
    n > 0 && switches[n - 1].1
}
