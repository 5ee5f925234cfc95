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
mod states;

pub use discrete::{CONTROLLABILITY_THRESHOLD, Discrete};
pub use linear::{Drive, LinearModel, ModelKind};
pub use params::{FlexParams, RigidParams};
pub use states::{CURRENT, FLEX_STATES, OMEGA, OMEGA_LOAD, PHI, RIGID_STATES, THETA};

#[cfg(test)]
mod tests;
