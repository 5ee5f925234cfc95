//! What draws: the actuator(s), and the model that aims the gimbal.

/// Which actuator draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Actuator {
    /// The servo gimbal (default).
    Gimbal,
    /// The two-mirror galvo scanner.
    Galvo,
    /// Both, visiting the same board points together.
    Both,
    /// The stepper pan/tilt (STEP/DIR drivers, open loop).
    Stepper,
}

impl Actuator {
    /// Name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Actuator::Gimbal => "gimbal",
            Actuator::Galvo => "galvo",
            Actuator::Both => "both",
            Actuator::Stepper => "stepper",
        }
    }

    /// Whether the gimbal takes part.
    pub fn uses_gimbal(self) -> bool {
        matches!(self, Actuator::Gimbal | Actuator::Both)
    }

    /// Whether the galvo takes part.
    pub fn uses_galvo(self) -> bool {
        matches!(self, Actuator::Galvo | Actuator::Both)
    }

    /// Whether the stepper pan/tilt draws.
    pub fn uses_stepper(self) -> bool {
        self == Actuator::Stepper
    }
}

/// Which kinematic model aims the gimbal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AimModel {
    /// The exact coupled model (SPEC §4.3), default.
    Exact,
    /// The seed's approximate model (SPEC §4.2), for comparison.
    Seed,
}
