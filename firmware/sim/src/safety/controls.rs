//! (g) The laser controls (on a board with them): no lit sample, gimbal
//! or galvo,
//!
//! * while the remote interlock reads open or the key switch off (from
//!   [`DARK_WITHIN_US`] after the opening on),
//! * without the emission indicator on, or before it has been on for the
//!   emission delay (the smallest `laser.emission_delay_s` accepted so
//!   far),
//! * without a manual reset since the interlock last opened or the key
//!   was last off: the indicator must have come on after that.
//!
//! Read from the inputs as the script set them and the indicator as the
//! board drove it, not from the firmware's own state.

use super::inputs::SafetyInputs;
use super::timeline::SettingsTimeline;
use super::violation::{DARK_WITHIN_US, Violation, ViolationKind};
use crate::controls::{ControlsRecord, level_at};

/// Lit stretches `(from µs, to µs)` of both lasers.
fn lit_stretches(inputs: &SafetyInputs<'_>) -> Vec<(u64, u64)> {
    let mut lit = Vec::new();
    let mut on_since = None;
    for &(t_us, on) in inputs.gimbal_laser {
        match (on, on_since) {
            (true, None) => on_since = Some(t_us),
            (false, Some(since)) => {
                lit.push((since, t_us));
                on_since = None;
            }
            _ => {}
        }
    }
    if let Some(since) = on_since {
        lit.push((since, inputs.end_us));
    }
    lit.extend(
        inputs
            .galvo
            .iter()
            .filter(|s| s.laser)
            .map(|s| (s.start_ns / 1000, s.last_ns() / 1000)),
    );
    lit
}

/// When the last change of `changes` at or before `t_us` to `level` was.
fn last_change_to(changes: &[(u64, bool)], level: bool, t_us: u64) -> Option<u64> {
    changes
        .iter()
        .take_while(|(t, _)| *t <= t_us)
        .filter(|(_, l)| *l == level)
        .map(|(t, _)| *t)
        .last()
}

/// Why a lit stretch `[from, to]` breaks the controls' rules, if it does.
fn breach(record: &ControlsRecord, delay_us: u64, from: u64, to: u64) -> Option<String> {
    let Some(indicator_on) = level_at(&record.indicator, from)
        .then(|| last_change_to(&record.indicator, true, from))
        .flatten()
    else {
        return Some("lit with the emission indicator off".into());
    };
    if from < indicator_on + delay_us {
        return Some(format!(
            "lit {:.3} s after the emission indicator came on (delay {:.3} s)",
            (from - indicator_on) as f64 / 1e6,
            delay_us as f64 / 1e6
        ));
    }
    for (name, changes) in [
        ("the interlock was open", &record.interlock_closed),
        ("the key was off", &record.key_on),
    ] {
        // Open at the reset, or opened since and still lit more than
        // DARK_WITHIN_US after (the firmware turns the indicator off when
        // it latches, so a new reset would be a new indicator start).
        let opened = (!level_at(changes, indicator_on))
            .then_some(indicator_on)
            .or_else(|| {
                changes
                    .iter()
                    .find(|(t, closed)| !closed && *t >= indicator_on && *t + DARK_WITHIN_US < to)
                    .map(|(t, _)| *t)
            });
        if let Some(t) = opened {
            return Some(format!(
                "lit until {:.3} ms although {name} at {:.3} ms without a reset since",
                to as f64 / 1000.0,
                t as f64 / 1000.0
            ));
        }
    }
    None
}

/// (e) The laser-controls rules (see the module docs); nothing to check
/// on a board without the controls.
pub(super) fn laser_controls_obeyed(
    inputs: &SafetyInputs<'_>,
    timeline: &SettingsTimeline,
) -> Vec<Violation> {
    let Some(record) = inputs.controls else {
        return Vec::new();
    };
    lit_stretches(inputs)
        .into_iter()
        .filter_map(|(from, to)| {
            let delay_us = (timeline.min_emission_delay_s(from) * 1e6) as u64;
            breach(record, delay_us, from, to).map(|detail| Violation {
                kind: ViolationKind::LitWithoutControls,
                t_us: from,
                detail,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests;
