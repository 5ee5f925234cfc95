//! The stepper step path's rows (issue 13): two axes stepping at 50 kHz
//! each within 20 % of the CPU, so a step event (both axes) has 20 % of
//! its 20 µs period.

use super::budgets::{Enforcement, Row};

/// Step event period at 50 kHz, µs.
const EVENT_US: f64 = 20.0;

/// The stepper's rows.
pub const STEPPER_ROWS: &[Row] = &[
    Row {
        id: "stepper.step_tick.event",
        what: "stepper step generator, per step event (two axes, a segment load every 75 events)",
        unit: "event",
        budget: Some((
            0.20 * EVENT_US,
            "20 % of a 50 kHz step event on two axes",
            Enforcement::Enforced,
        )),
    },
    Row {
        id: "stepper.step_tick.event_one_pulse",
        what: "stepper step event with the one-pulse timer's values (DIR change, compare, reload, modes; without the five register stores)",
        unit: "event",
        budget: Some((
            0.20 * EVENT_US,
            "20 % of a 50 kHz step event on two axes",
            Enforcement::Enforced,
        )),
    },
    Row {
        id: "stepper.step_tick.segment",
        what: "stepper step generator, an event that loads a new segment",
        unit: "segment",
        budget: Some((
            0.20 * EVENT_US,
            "20 % of a 50 kHz step event on two axes",
            Enforcement::Enforced,
        )),
    },
    Row {
        id: "stepper.prep.segment",
        what: "stepper segment prep (f64 profile, low-priority task)",
        unit: "segment",
        budget: None,
    },
];
