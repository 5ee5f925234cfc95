//! Galvo motor models and their exact zero-order-hold discretisation.
//!
//! * **Rigid**: state `Z = (θ, ω, I)`, input voltage `U`:
//!   `U = Kt·ω + L·dI/dt + R·I`, `Kt·I = J·dω/dt`.
//! * **Flexible** (two inertias coupled by a torsional stiffness `K`):
//!   state `Z = (θ, ω, I, φ, ω_φ)` (motor angle and speed, current, load
//!   angle and speed): `Kt·I − K(θ−φ) = Jm·θ''`, `K(θ−φ) = Jl·φ''`, same
//!   electrical equation.
//!
//! The first three state components have the same meaning in both models
//! ([`THETA`], [`OMEGA`], [`CURRENT`]), so code that only looks at the motor
//! works for both.

mod discrete;
mod linear;
mod params;

pub use discrete::{CONTROLLABILITY_THRESHOLD, Discrete};
pub use linear::{Drive, LinearModel, ModelKind};
pub use params::{FlexParams, RigidParams};

/// Index of the motor angle θ (rad) in every state vector.
pub const THETA: usize = 0;
/// Index of the motor speed ω (rad/s).
pub const OMEGA: usize = 1;
/// Index of the coil current I (A).
pub const CURRENT: usize = 2;
/// Index of the load (mirror) angle φ (rad) in the flexible model's state.
pub const PHI: usize = 3;
/// Index of the load speed ω_φ (rad/s) in the flexible model's state.
pub const OMEGA_LOAD: usize = 4;

/// Number of states of the rigid model.
pub const RIGID_STATES: usize = 3;
/// Number of states of the flexible model.
pub const FLEX_STATES: usize = 5;

#[cfg(test)]
mod tests;
