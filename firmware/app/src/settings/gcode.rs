//! G-code's saved settings (ids 190–199): grbl's `$11` junction
//! deviation, which the G-code look-ahead of the gimbal and the stepper
//! plans with (`$N=` sets it like the other `$` settings mapped to
//! parameters; `save` keeps it).

use super::spec::{ParamSpec, Precision, Slot, real};

/// Parameters 190–199.
pub(super) const GCODE_PARAMS: [ParamSpec; 1] = [real!(
    190,
    "gcode.junction_mm",
    0.0,
    10.0,
    "G-code junction deviation ($11), mm",
    |s| s.gcode_junction_mm
)];
