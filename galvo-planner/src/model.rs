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

use crate::error::{Error, positive};
use crate::linalg::{
    Matrix, Vector, expm_and_integral, identity, mat_mul, mat_vec, spd_solve_scaled, vec_add,
};

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
        let kt = positive("kt_nm_per_a", self.kt_nm_per_a)?;
        let j = positive("j_kg_m2", self.j_kg_m2)?;
        let l = positive("l_h", self.l_h)?;
        let r = positive("r_ohm", self.r_ohm)?;
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
        let kt = positive("kt_nm_per_a", self.kt_nm_per_a)?;
        let jm = positive("jm_kg_m2", self.jm_kg_m2)?;
        let jl = positive("jl_kg_m2", self.jl_kg_m2)?;
        let k = positive("k_nm_per_rad", self.k_nm_per_rad)?;
        let l = positive("l_h", self.l_h)?;
        let r = positive("r_ohm", self.r_ohm)?;
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

fn check_u_max(u_max_v: f64) -> Result<f64, Error> {
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
    fn new(
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

    /// Exact zero-order-hold discretisation with sample period `ts_s`:
    /// `Ad = e^{A·Ts}`, `Bd = ∫₀^Ts e^{A·τ} dτ · B` (scaling and squaring, see
    /// [`expm_and_integral`]).
    ///
    /// Fails with [`Error::InvalidSamplePeriod`] for a zero, negative or
    /// non-finite period and with [`Error::NotControllable`] when the sampled
    /// system loses controllability (pathological sampling of an oscillatory
    /// mode: its frequency is a multiple of half the sample rate).
    pub fn discretize(&self, ts_s: f64) -> Result<Discrete<S>, Error> {
        if !ts_s.is_finite() || ts_s <= 0.0 {
            return Err(Error::InvalidSamplePeriod { ts_s });
        }
        let (ad, phi) = expm_and_integral(&self.a, ts_s);
        let bd = mat_vec(&phi, &self.b);
        if ad.iter().flatten().chain(bd.iter()).any(|v| !v.is_finite()) {
            return Err(Error::InvalidSamplePeriod { ts_s });
        }
        let disc = Discrete {
            ad,
            bd,
            ts_s,
            model: *self,
            rigid_modes: crate::fast_optimal::RigidModes::new(self, ts_s),
        };
        if disc.controllability_ratio() < CONTROLLABILITY_THRESHOLD {
            return Err(Error::NotControllable);
        }
        Ok(disc)
    }
}

/// Smallest acceptable pivot ratio of the scaled reachability Gramian (see
/// [`Discrete::controllability_ratio`]). Controllable reference models sit
/// around 1e-9…1e-3; exact loss of controllability gives ~1e-16.
pub const CONTROLLABILITY_THRESHOLD: f64 = 1e-12;

/// The sampled model `Z(k+1) = Ad·Z(k) + Bd·U(k)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Discrete<const S: usize> {
    ad: Matrix<S, S>,
    bd: Vector<S>,
    ts_s: f64,
    model: LinearModel<S>,
    /// Modal data for the single-precision time-optimal planner (rigid
    /// models it covers), rebuilt with the model.
    rigid_modes: Option<crate::fast_optimal::RigidModes>,
}

impl<const S: usize> Discrete<S> {
    /// `Ad`.
    pub fn ad(&self) -> &Matrix<S, S> {
        &self.ad
    }
    /// `Bd`.
    pub fn bd(&self) -> &Vector<S> {
        &self.bd
    }
    /// Sample period, s.
    pub fn ts_s(&self) -> f64 {
        self.ts_s
    }
    /// The continuous model this was sampled from.
    pub fn model(&self) -> &LinearModel<S> {
        &self.model
    }
    /// Voltage limit, V.
    pub fn u_max_v(&self) -> f64 {
        self.model.u_max_v
    }

    /// Modal data of the single-precision time-optimal planner.
    pub(crate) fn rigid_modes(&self) -> Option<&crate::fast_optimal::RigidModes> {
        self.rigid_modes.as_ref()
    }

    /// One step: `Ad·z + Bd·u`.
    pub fn step(&self, z: &Vector<S>, u_v: f64) -> Vector<S> {
        let mut next = mat_vec(&self.ad, z);
        for (n, b) in next.iter_mut().zip(self.bd.iter()) {
            *n += b * u_v;
        }
        next
    }

    /// Simulates the voltage sequence `u_v` from `z0` and calls
    /// `visit(k, &Z(k), u_k)` for k = 0..=len (with `u = 0` on the last
    /// call, whose state is the final one). Returns the final state.
    pub fn simulate(
        &self,
        z0: &Vector<S>,
        u_v: &[f64],
        mut visit: impl FnMut(usize, &Vector<S>, f64),
    ) -> Vector<S> {
        let mut z = *z0;
        for (k, &u) in u_v.iter().enumerate() {
            visit(k, &z, u);
            z = self.step(&z, u);
        }
        visit(u_v.len(), &z, 0.0);
        z
    }

    /// `(Ad^q, Σ_{j<q} Ad^j·Bd)`: the free response matrix after `q` samples
    /// and the response to `q` samples of unit input, by binary powering
    /// (O(log q) small matrix products).
    pub fn power(&self, q: usize) -> (Matrix<S, S>, Vector<S>) {
        let mut result = (identity::<S>(), [0.0; S]);
        let mut base = (self.ad, self.bd);
        let mut q = q;
        while q > 0 {
            if q & 1 == 1 {
                result = compose(&result, &base);
            }
            q >>= 1;
            if q > 0 {
                base = compose(&base, &base);
            }
        }
        result
    }

    /// `Ad^q·Bd`: the effect on the state `q` samples later of a unit input
    /// held for one sample.
    pub fn impulse(&self, q: usize) -> Vector<S> {
        let (aq, _) = self.power(q);
        mat_vec(&aq, &self.bd)
    }

    /// Conditioning of the reachability Gramian over a horizon of `8·S`
    /// samples after symmetric diagonal scaling: the smallest/largest pivot
    /// ratio of its elimination. Near 1e-16 means some direction of the state
    /// space cannot be reached.
    pub fn controllability_ratio(&self) -> f64 {
        let mut w = [[0.0; S]; S];
        let mut g = self.bd;
        for _ in 0..(8 * S) {
            accumulate_outer(&mut w, &g);
            g = mat_vec(&self.ad, &g);
        }
        match spd_solve_scaled(&w, &[1.0; S]) {
            Some((_, ratio)) => ratio,
            None => 0.0,
        }
    }
}

/// Composition of two (Ad^q, S(q)) pairs: q1 + q2 samples.
fn compose<const S: usize>(
    p1: &(Matrix<S, S>, Vector<S>),
    p2: &(Matrix<S, S>, Vector<S>),
) -> (Matrix<S, S>, Vector<S>) {
    let a = mat_mul(&p1.0, &p2.0);
    let s = vec_add(&p1.1, &mat_vec(&p1.0, &p2.1));
    (a, s)
}

/// `w += g·gᵀ`.
pub(crate) fn accumulate_outer<const S: usize>(w: &mut Matrix<S, S>, g: &Vector<S>) {
    for (row, gi) in w.iter_mut().zip(g.iter()) {
        for (x, gj) in row.iter_mut().zip(g.iter()) {
            *x += gi * gj;
        }
    }
}

#[cfg(test)]
mod tests;
