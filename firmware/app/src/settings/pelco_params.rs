//! The PELCO port's rows of the parameter table (ids 200–209; the
//! settings themselves are in `pelco.rs`).

use super::spec::{ParamSpec, Precision, Slot, choice, count, real};
use super::values::Settings;

/// Parameters 200–209.
pub(super) const PELCO_PARAMS: [ParamSpec; 3] = [
    count!(
        200,
        "pelco.address",
        1.0,
        255.0,
        "PELCO device address",
        |s| s.pelco.address
    ),
    ParamSpec {
        id: 201,
        name: "pelco.baud",
        min: 2400.0,
        max: 19200.0,
        min_magnitude: 0.0,
        precision: Precision::F64,
        help: "PELCO port baud rate: 2400, 4800, 9600 or 19200",
        slot: Slot::Baud(baud),
    },
    real!(
        202,
        "pelco.timeout_s",
        0.0,
        3600.0,
        "PELCO motion timeout without frames, s (0: off)",
        |s| s.pelco.motion_timeout_s
    ),
];

fn baud(s: &mut Settings) -> &mut f64 {
    &mut s.pelco.baud
}
