//! Exact zero-order-hold discretisation and the sampled model.

use super::linear::{LinearModel, ModelKind};
use crate::error::Error;
use crate::linalg::{
    Matrix, Vector, accumulate_outer, expm_and_integral, identity, mat_mul, mat_vec,
    spd_solve_scaled, vec_add,
};
use crate::rigid_modes::RigidModes;

impl<const S: usize> LinearModel<S> {
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
        let (ad, phi) = expm_and_integral(self.a(), ts_s);
        let bd = mat_vec(&phi, self.b());
        if ad.iter().flatten().chain(bd.iter()).any(|v| !v.is_finite()) {
            return Err(Error::InvalidSamplePeriod { ts_s });
        }
        let disc = Discrete {
            ad,
            bd,
            ts_s,
            model: *self,
            rigid_modes: match self.kind() {
                ModelKind::Rigid => {
                    RigidModes::new(self.a(), self.drive().kt_nm_per_a, self.u_max_v(), ts_s)
                }
                ModelKind::Flexible => None,
            },
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
    rigid_modes: Option<RigidModes>,
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
        self.model.u_max_v()
    }

    /// Modal data of the single-precision time-optimal planner.
    pub(crate) fn rigid_modes(&self) -> Option<&RigidModes> {
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
