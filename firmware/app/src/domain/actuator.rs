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
}

impl Actuator {
    /// Name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Actuator::Gimbal => "gimbal",
            Actuator::Galvo => "galvo",
            Actuator::Both => "both",
        }
    }

    /// Whether the gimbal takes part.
    pub fn uses_gimbal(self) -> bool {
        self != Actuator::Galvo
    }

    /// Whether the galvo takes part.
    pub fn uses_galvo(self) -> bool {
        self != Actuator::Gimbal
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
