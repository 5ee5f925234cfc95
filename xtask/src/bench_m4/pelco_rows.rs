//! The PELCO port's rows (issue 23): decoding one frame and the session
//! turning it into the product's commands. Frames can arrive back to back:
//! at the port's fastest rate (19 200 baud, 8N1) a PELCO-D frame of 7
//! bytes takes 3.65 ms on the wire (PELCO-P's 8: 4.17 ms). A frame may use
//! a quarter of that, so the port keeps up with a saturated bus while the
//! galvo loop's refills and the sequencer keep the rest of the CPU.

use super::budgets::{Enforcement, Row};

/// A PELCO-D frame (7 bytes of 10 bits) at 19 200 baud, µs.
const FRAME_US: f64 = 7.0 * 10.0 / 19_200.0 * 1e6;

/// A quarter of the shortest frame time.
const fn frame_budget() -> Option<(f64, &'static str, Enforcement)> {
    Some((
        0.25 * FRAME_US,
        "25 % of a back-to-back PELCO-D frame at 19 200 baud (3.65 ms)",
        Enforcement::Enforced,
    ))
}

/// The PELCO rows.
pub const PELCO_ROWS: &[Row] = &[
    Row {
        id: "pelco.frame.move",
        what: "PELCO frame: decode + session, pan right / tilt up from rest (two 50 ms jogs queued)",
        unit: "frame",
        budget: frame_budget(),
    },
    Row {
        id: "pelco.frame.set_pan",
        what: "PELCO frame: decode + session, absolute pan 25.5° (goto of the point)",
        unit: "frame",
        budget: frame_budget(),
    },
    Row {
        id: "pelco.frame.query_pan",
        what: "PELCO frame: decode + session, pan query (reply frame)",
        unit: "frame",
        budget: frame_budget(),
    },
    Row {
        id: "pelco.frame.goto_preset",
        what: "PELCO frame: decode + session, go to preset (preset goto command)",
        unit: "frame",
        budget: frame_budget(),
    },
    Row {
        id: "sweep.pelco.frame",
        what: "PELCO frame: decode + session, worst of a seeded sweep over every frame kind of both dialects",
        unit: "frame",
        budget: frame_budget(),
    },
];
