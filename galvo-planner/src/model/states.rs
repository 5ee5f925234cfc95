//! The state vectors' layout: which component is what, and how many.

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
