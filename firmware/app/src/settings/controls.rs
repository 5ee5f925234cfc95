//! The laser controls' saved settings (ids 210–219): the emission
//! indicator's lead time before the laser may emit after `arm`
//! (`docs/laser-safety.md`).

use super::spec::{ParamSpec, Precision, Slot, real};

/// Parameters 210–219.
pub(super) const CONTROLS_PARAMS: [ParamSpec; 1] = [real!(
    210,
    "laser.emission_delay_s",
    1.0,
    60.0,
    Precision::F32,
    "emission indicator lead after arm, s",
    |s| s.emission_delay_s
)];
