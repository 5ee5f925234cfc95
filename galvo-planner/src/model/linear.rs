//! The continuous linear model `Z' = A·Z + B·U` and its drive parameters.

use crate::error::Error;
use crate::linalg::{Matrix, Vector};

pub(super) fn check_u_max(u_max_v: f64) -> Result<f64, Error> {
    if u_max_v.is_finite() && u_max_v > 0.0 {
        Ok(u_max_v)
    } else {
        Err(Error::UmaxTooSmall { u_max_v })
    }
}

/// Which physical model a [`LinearModel`] describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    /// Rigid rotor + mirror, 3 states.
    Rigid,
    /// Two inertias and a torsional spring, 5 states.
    Flexible,
}

/// The lumped drive parameters (for the flexible model `j_kg_m2` is the
/// total inertia Jm + Jl): what the baseline profiles' limits and inverse
/// dynamics use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drive {
    /// Torque constant, N·m/A.
    pub kt_nm_per_a: f64,
    /// Total moving inertia, kg·m².
    pub j_kg_m2: f64,
    /// Coil inductance, H.
    pub l_h: f64,
    /// Coil resistance, Ω.
    pub r_ohm: f64,
}

/// A validated continuous-time model `Ż = A·Z + B·U` with `S` states.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearModel<const S: usize> {
    a: Matrix<S, S>,
    b: Vector<S>,
    u_max_v: f64,
    kind: ModelKind,
    drive: Drive,
    /// States that equal the position at rest (θ, and φ for the flexible model).
    position_states: [bool; S],
}

impl<const S: usize> LinearModel<S> {
    pub(super) fn new(
        a: Matrix<S, S>,
        b: Vector<S>,
        u_max_v: f64,
        kind: ModelKind,
        drive: Drive,
        position_states: [bool; S],
    ) -> Result<Self, Error> {
        if a.iter().flatten().chain(b.iter()).any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                name: "model matrix (parameter ratio overflows)",
            });
        }
        Ok(Self {
            a,
            b,
            u_max_v,
            kind,
            drive,
            position_states,
        })
    }

    /// The state matrix `A`.
    pub fn a(&self) -> &Matrix<S, S> {
        &self.a
    }
    /// The input vector `B`.
    pub fn b(&self) -> &Vector<S> {
        &self.b
    }
    /// Voltage limit, V.
    pub fn u_max_v(&self) -> f64 {
        self.u_max_v
    }
    /// Rigid or flexible.
    pub fn kind(&self) -> ModelKind {
        self.kind
    }
    /// Lumped drive parameters.
    pub fn drive(&self) -> &Drive {
        &self.drive
    }

    /// Which state components are angles (θ, and φ for the flexible model):
    /// at rest they all equal the position, the others are zero.
    pub fn position_states(&self) -> &[bool; S] {
        &self.position_states
    }

    /// The state at rest at mechanical angle `theta_rad` (all angles equal,
    /// all speeds and the current zero). Rest states are equilibria with
    /// `U = 0`.
    pub fn rest_state(&self, theta_rad: f64) -> Vector<S> {
        core::array::from_fn(|i| {
            if self.position_states.get(i).copied().unwrap_or(false) {
                theta_rad
            } else {
                0.0
            }
        })
    }

    /// Same model with another voltage limit.
    pub fn with_u_max_v(mut self, u_max_v: f64) -> Result<Self, Error> {
        self.u_max_v = check_u_max(u_max_v)?;
        Ok(self)
    }
}
