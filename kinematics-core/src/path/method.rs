//! What the interpolators share: the step limit, the direction of an arc,
//! the comparison method's criterion (see [`super`]) and the step check.

use crate::error::Error;
use crate::numeric::finite;

/// Most unit moves one interpolation may take.
pub const MAX_STEPS: u32 = 1 << 24;

/// Direction of travel around a circle (board frame: x right, y up).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Rotation {
    /// Clockwise (seed `SorN = 1`, G-code G2).
    #[default]
    Cw,
    /// Counter-clockwise (seed `SorN = 2`, G-code G3).
    Ccw,
}

impl Rotation {
    /// −1 for clockwise (angles decrease), +1 for counter-clockwise.
    pub fn sign(self) -> f64 {
        match self {
            Rotation::Cw => -1.0,
            Rotation::Ccw => 1.0,
        }
    }
}

/// Where the comparison method evaluates its deviation function (see the
/// module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Criterion {
    /// At the step midpoint: within ½ step per axis of the path.
    #[default]
    Midpoint,
    /// At the current point, as the seed: within 1 step of the path.
    Seed,
}

/// Checks a step length (cm): finite and > 0.
pub(super) fn check_step(step_cm: f64) -> Result<f64, Error> {
    if finite(step_cm, "step_cm")? <= 0.0 {
        return Err(Error::InvalidConfig {
            what: "step_cm must be > 0",
        });
    }
    Ok(step_cm)
}
