//! Physical parameters of the rigid and flexible galvos and the continuous
//! models built from them.

use super::linear::{Drive, LinearModel, ModelKind, check_u_max};
use super::states::{FLEX_STATES, RIGID_STATES};
use crate::error::{Error, positive};

/// Parameters of the rigid galvo model (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidParams {
    /// Torque constant (= back-EMF constant), N·m/A (V·s/rad).
    pub kt_nm_per_a: f64,
    /// Rotor + mirror inertia, kg·m².
    pub j_kg_m2: f64,
    /// Coil inductance, H.
    pub l_h: f64,
    /// Coil resistance, Ω.
    pub r_ohm: f64,
    /// Drive voltage limit |U| ≤ `u_max_v`, V.
    pub u_max_v: f64,
}

impl RigidParams {
    /// The reference galvo of SPEC §6.
    pub const REFERENCE: Self = Self {
        kt_nm_per_a: 0.0115,
        j_kg_m2: 2.0e-8,
        l_h: 180.0e-6,
        r_ohm: 2.8,
        u_max_v: 24.0,
    };

    /// Validates the parameters and builds the continuous model.
    pub fn model(&self) -> Result<LinearModel<RIGID_STATES>, Error> {
        let kt = positive(self.kt_nm_per_a, "kt_nm_per_a")?;
        let j = positive(self.j_kg_m2, "j_kg_m2")?;
        let l = positive(self.l_h, "l_h")?;
        let r = positive(self.r_ohm, "r_ohm")?;
        let u_max_v = check_u_max(self.u_max_v)?;
        let a = [[0.0, 1.0, 0.0], [0.0, 0.0, kt / j], [0.0, -kt / l, -r / l]];
        let b = [0.0, 0.0, 1.0 / l];
        LinearModel::new(
            a,
            b,
            u_max_v,
            ModelKind::Rigid,
            Drive {
                kt_nm_per_a: kt,
                j_kg_m2: j,
                l_h: l,
                r_ohm: r,
            },
            [true, false, false],
        )
    }
}

/// Parameters of the flexible (two-inertia) galvo model (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlexParams {
    /// Torque constant, N·m/A.
    pub kt_nm_per_a: f64,
    /// Motor (rotor) inertia, kg·m².
    pub jm_kg_m2: f64,
    /// Load (mirror) inertia, kg·m².
    pub jl_kg_m2: f64,
    /// Torsional stiffness of the shaft between them, N·m/rad.
    pub k_nm_per_rad: f64,
    /// Coil inductance, H.
    pub l_h: f64,
    /// Coil resistance, Ω.
    pub r_ohm: f64,
    /// Drive voltage limit, V.
    pub u_max_v: f64,
}

impl FlexParams {
    /// The reference flexible galvo of SPEC §6: the rigid reference split into
    /// Jm = Jl = 1.0e-8 kg·m² with the first torsional resonance at 10 kHz.
    pub const REFERENCE: Self = Self {
        kt_nm_per_a: 0.0115,
        jm_kg_m2: 1.0e-8,
        jl_kg_m2: 1.0e-8,
        k_nm_per_rad: Self::stiffness_for_resonance(1.0e-8, 1.0e-8, 10.0e3),
        l_h: 180.0e-6,
        r_ohm: 2.8,
        u_max_v: 24.0,
    };

    /// Shaft stiffness that puts the free–free torsional resonance
    /// `f = (1/2π)·√(K·(1/Jm + 1/Jl))` at `f_hz`.
    pub const fn stiffness_for_resonance(jm_kg_m2: f64, jl_kg_m2: f64, f_hz: f64) -> f64 {
        let w = 2.0 * core::f64::consts::PI * f_hz;
        w * w * jm_kg_m2 * jl_kg_m2 / (jm_kg_m2 + jl_kg_m2)
    }

    /// The free–free torsional resonance frequency, Hz (mechanics only; the
    /// coil's back-EMF damping shifts the coupled mode slightly).
    pub fn resonance_hz(&self) -> f64 {
        libm::sqrt(self.k_nm_per_rad * (1.0 / self.jm_kg_m2 + 1.0 / self.jl_kg_m2))
            / (2.0 * core::f64::consts::PI)
    }

    /// Validates the parameters and builds the continuous model.
    pub fn model(&self) -> Result<LinearModel<FLEX_STATES>, Error> {
        let kt = positive(self.kt_nm_per_a, "kt_nm_per_a")?;
        let jm = positive(self.jm_kg_m2, "jm_kg_m2")?;
        let jl = positive(self.jl_kg_m2, "jl_kg_m2")?;
        let k = positive(self.k_nm_per_rad, "k_nm_per_rad")?;
        let l = positive(self.l_h, "l_h")?;
        let r = positive(self.r_ohm, "r_ohm")?;
        let u_max_v = check_u_max(self.u_max_v)?;
        // State (θ, ω, I, φ, ω_φ).
        let a = [
            [0.0, 1.0, 0.0, 0.0, 0.0],
            [-k / jm, 0.0, kt / jm, k / jm, 0.0],
            [0.0, -kt / l, -r / l, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 1.0],
            [k / jl, 0.0, 0.0, -k / jl, 0.0],
        ];
        let b = [0.0, 0.0, 1.0 / l, 0.0, 0.0];
        LinearModel::new(
            a,
            b,
            u_max_v,
            ModelKind::Flexible,
            Drive {
                kt_nm_per_a: kt,
                j_kg_m2: jm + jl,
                l_h: l,
                r_ohm: r,
            },
            [true, false, false, true, false],
        )
    }
}
