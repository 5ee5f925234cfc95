//! Jump plans: the one result type of every planner, below the planners
//! and the dispatcher ([`jump`](crate::jump)).
//!
//! A [`JumpPlan`] is small and `Copy`: it stores the sampled model, the start
//! and target states, the number of samples `N` and a compact *input law*
//! from which the voltage of every sample is regenerated on demand
//! ([`JumpPlan::write_u_v`], [`JumpPlan::for_each_input_rev`]). Nothing is
//! allocated; the caller (or the [`Integrator`](crate::integrator::Integrator)) owns
//! the sample buffer, and a plan that needs more samples than the capacity
//! given to the planner is refused with [`Error::CapacityExceeded`].

use crate::bang_bang::{BangBang, FastLaw, FastMove, OptimalInfo};
use crate::error::Error;
use crate::linalg::{Vector, at, dot, mat_vec, vec_add, vec_scale};
use crate::model::Discrete;
use crate::motion_profile::Profile;

/// Upper bound on the samples of any plan, whatever capacity the caller
/// offers (2²² samples = 42 s at Ts = 10 µs): planning is O(N) per
/// evaluation, so this keeps absurd requests from running for hours.
pub const MAX_PLAN_SAMPLES: usize = 1 << 22;

/// The capacity a planner actually works with.
pub(crate) fn effective_capacity(capacity: usize) -> usize {
    capacity.min(MAX_PLAN_SAMPLES)
}

/// Which planner produced a [`JumpPlan`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodKind {
    /// Zero-length move (start = target).
    Hold,
    /// Minimum-energy input over a caller-chosen number of samples.
    MinEnergy,
    /// Bisection planner (the patent's method; user-facing name `seed`).
    Bisection,
    /// Time-optimal planner.
    TimeOptimal,
    /// Trapezoidal baseline.
    TCurve,
    /// S-curve baseline.
    SCurve,
}

impl MethodKind {
    /// Short lower-case name.
    pub fn name(&self) -> &'static str {
        match self {
            MethodKind::Hold => "hold",
            MethodKind::MinEnergy => "min-energy",
            MethodKind::Bisection => "seed",
            MethodKind::TimeOptimal => "optimal",
            MethodKind::TCurve => "tcurve",
            MethodKind::SCurve => "scurve",
        }
    }
}

/// Planner-specific diagnostics attached to a plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlanInfo {
    /// Nothing to report.
    None,
    /// Bisection bracket and evaluation count of the bisection planner.
    Bisection(BisectionInfo),
    /// Switching structure of the time-optimal planner.
    Optimal(OptimalInfo),
    /// The baseline profile (its duration and limits).
    Profile(Profile),
}

/// How each sample's voltage is generated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum InputLaw<const S: usize> {
    /// No samples.
    Hold,
    /// `u_k = (Ad^{N−1−k}·Bd)ᵀ·λ`.
    MinEnergy { lambda: Vector<S> },
    /// Sample-averaged bang-bang with a free last sample.
    BangBang(BangBang),
    /// The single-precision planner's bang-bang or dead-beat input, in
    /// the `f32` it was solved in (its diagnostics derived from it).
    Fast(FastLaw),
    /// Inverse-dynamics voltage of a profile plus a minimum-norm correction
    /// `(Ad^{N−1−k}·Bd)ᵀ·λ` that makes it land exactly.
    Profile { profile: Profile, lambda: Vector<S> },
}

/// A planned rest-to-rest (or state-to-state) move on the sample grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JumpPlan<const S: usize> {
    disc: Discrete<S>,
    z0: Vector<S>,
    z1: Vector<S>,
    samples: usize,
    law: InputLaw<S>,
    method: MethodKind,
    max_abs_u_v: f64,
    info: PlanInfo,
}

impl<const S: usize> JumpPlan<S> {
    /// Builds a plan and measures its peak voltage (one pass over the inputs).
    pub(crate) fn new(
        disc: &Discrete<S>,
        z0: Vector<S>,
        z1: Vector<S>,
        samples: usize,
        law: InputLaw<S>,
        method: MethodKind,
        info: PlanInfo,
    ) -> Self {
        let mut plan = Self::with_peak(disc, z0, z1, samples, law, method, info, 0.0);
        let mut peak = 0.0f64;
        plan.for_each_input_rev(|_, u| peak = peak.max(libm::fabs(u)));
        plan.max_abs_u_v = peak;
        plan
    }

    /// Builds a plan whose peak voltage the planner already knows (no pass
    /// over the inputs).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn with_peak(
        disc: &Discrete<S>,
        z0: Vector<S>,
        z1: Vector<S>,
        samples: usize,
        law: InputLaw<S>,
        method: MethodKind,
        info: PlanInfo,
        max_abs_u_v: f64,
    ) -> Self {
        Self {
            disc: *disc,
            z0,
            z1,
            samples,
            law,
            method,
            max_abs_u_v,
            info,
        }
    }

    /// A zero-length plan that holds `z0`.
    pub(crate) fn hold(disc: &Discrete<S>, z0: Vector<S>) -> Self {
        Self::new(
            disc,
            z0,
            z0,
            0,
            InputLaw::Hold,
            MethodKind::Hold,
            PlanInfo::None,
        )
    }

    /// The plan of a move the single-precision planner solved.
    pub(crate) fn fast(disc: &Discrete<S>, mv: FastMove) -> Self {
        let model = disc.model();
        let z0 = model.rest_state(mv.from_rad);
        match mv.law {
            Some(law) => Self {
                disc: *disc,
                z0,
                z1: model.rest_state(mv.to_rad),
                samples: law.n,
                law: InputLaw::Fast(law),
                method: MethodKind::TimeOptimal,
                max_abs_u_v: law.peak_abs_u_v(disc.u_max_v()),
                info: PlanInfo::None,
            },
            None => Self::hold(disc, z0),
        }
    }

    /// The same plan reported as made by `method` with `info`.
    pub(crate) fn relabel(mut self, method: MethodKind, info: PlanInfo) -> Self {
        self.method = method;
        self.info = info;
        self
    }

    /// Number of voltage samples `N` (the move lasts `N·Ts`; the CSV of the
    /// move has `N + 1` rows).
    pub fn samples(&self) -> usize {
        self.samples
    }
    /// Sample period, s.
    pub fn ts_s(&self) -> f64 {
        self.disc.ts_s()
    }
    /// Move time `N·Ts`, s.
    pub fn move_time_s(&self) -> f64 {
        self.samples as f64 * self.disc.ts_s()
    }
    /// Which planner made this plan.
    pub fn method(&self) -> MethodKind {
        self.method
    }
    /// The sampled model the plan is for.
    pub fn discrete(&self) -> &Discrete<S> {
        &self.disc
    }
    /// Start state.
    pub fn start_state(&self) -> &Vector<S> {
        &self.z0
    }
    /// Target state.
    pub fn target_state(&self) -> &Vector<S> {
        &self.z1
    }
    /// Largest |voltage| of any sample, V.
    pub fn max_abs_u_v(&self) -> f64 {
        self.max_abs_u_v
    }
    /// Whether every sample respects the model's voltage limit.
    pub fn within_voltage_limit(&self) -> bool {
        self.max_abs_u_v <= self.disc.u_max_v()
    }
    /// Planner diagnostics.
    pub fn info(&self) -> PlanInfo {
        match &self.law {
            InputLaw::Fast(law) => PlanInfo::Optimal(law.info(self.disc.u_max_v())),
            _ => self.info,
        }
    }

    /// Calls `f(k, u_k)` for every sample, in the order k = N−1, N−2, …, 0
    /// (the order in which the minimum-energy law is cheapest to evaluate).
    pub fn for_each_input_rev(&self, mut f: impl FnMut(usize, f64)) {
        let n = self.samples;
        match &self.law {
            InputLaw::Hold => {}
            InputLaw::MinEnergy { lambda } => {
                let mut g = *self.disc.bd();
                for j in 0..n {
                    f(n - 1 - j, dot(&g, lambda));
                    g = mat_vec(self.disc.ad(), &g);
                }
            }
            InputLaw::BangBang(bb) => {
                for k in (0..n).rev() {
                    f(k, bb.u_v(k));
                }
            }
            InputLaw::Fast(law) => {
                match (law.bang_bang(self.disc.u_max_v()), law.dead_beat_u_v()) {
                    (Some(bb), _) => (0..n).rev().for_each(|k| f(k, bb.u_v(k))),
                    (None, u_v) => {
                        let u_v = u_v.unwrap_or_default();
                        for k in (0..n.min(3)).rev() {
                            f(k, u_v.get(k).copied().unwrap_or(0.0));
                        }
                    }
                }
            }
            InputLaw::Profile { profile, lambda } => {
                let drive = self.disc.model().drive();
                let ts = self.disc.ts_s();
                let mut g = *self.disc.bd();
                for j in 0..n {
                    let k = n - 1 - j;
                    f(k, profile.average_u_v(drive, ts, k) + dot(&g, lambda));
                    g = mat_vec(self.disc.ad(), &g);
                }
            }
        }
    }

    /// [`Self::for_each_input_rev`] with each `u_k` rounded to `f32`
    /// (what the integrator runs on), the bang-bang law's saturated
    /// samples without per-sample `f64` work.
    pub fn for_each_input_rev_f32(&self, mut f: impl FnMut(usize, f32)) {
        match &self.law {
            InputLaw::BangBang(bb) => bb.for_each_rev_f32(f),
            InputLaw::Fast(law) => match law.bang_bang(self.disc.u_max_v()) {
                Some(bb) => bb.for_each_rev_f32(f),
                None => self.for_each_input_rev(|k, u| f(k, u as f32)),
            },
            _ => self.for_each_input_rev(|k, u| f(k, u as f32)),
        }
    }

    /// Writes the `N` voltages into `out[..N]` and returns `N`.
    pub fn write_u_v(&self, out: &mut [f64]) -> Result<usize, Error> {
        if out.len() < self.samples {
            return Err(Error::CapacityExceeded {
                needed: self.samples,
                capacity: out.len(),
            });
        }
        self.for_each_input_rev(|k, u| {
            if let Some(slot) = out.get_mut(k) {
                *slot = u;
            }
        });
        Ok(self.samples)
    }

    /// `|final_state() − target|` per state component.
    pub fn landing_error(&self) -> Vector<S> {
        let z = self.final_state();
        core::array::from_fn(|i| libm::fabs(at(&z, i) - at(&self.z1, i)))
    }

    /// Final state by superposition, `Ad^N·Z0 + Σ Ad^{N−1−k}·Bd·u_k`, without
    /// a sample buffer.
    pub fn final_state(&self) -> Vector<S> {
        let (an, _) = self.disc.power(self.samples);
        let mut z = mat_vec(&an, &self.z0);
        let mut g = *self.disc.bd();
        // Inputs arrive as k = N−1, N−2, … i.e. with g = Ad^0·Bd, Ad^1·Bd, …
        self.for_each_input_rev(|_, u| {
            z = vec_add(&z, &vec_scale(&g, u));
            g = mat_vec(self.disc.ad(), &g);
        });
        z
    }
}

/// What the bisection planner did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BisectionInfo {
    /// Bracket before the halvings, s.
    pub initial_bracket_s: (f64, f64),
    /// Bracket after the halvings, s (`Tmin` infeasible, `Tmax` feasible and
    /// used for the plan when the bracket was automatic).
    pub final_bracket_s: (f64, f64),
    /// Halvings carried out (`min(p, MAX_HALVINGS)`).
    pub halvings: u32,
    /// Minimum-energy evaluations (bracketing + halvings + final).
    pub evaluations: u32,
}

/// Plans of the two mirror axes of one jump (laser off).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct XyJump<const S: usize> {
    /// X mirror plan.
    pub x: JumpPlan<S>,
    /// Y mirror plan.
    pub y: JumpPlan<S>,
}

impl<const S: usize> XyJump<S> {
    /// Samples until both axes have landed (the longer move governs).
    pub fn samples(&self) -> usize {
        self.x.samples().max(self.y.samples())
    }
}

/// Checks a state vector for NaN/∞.
pub(crate) fn finite_state<const S: usize>(name: &'static str, z: &Vector<S>) -> Result<(), Error> {
    if z.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(Error::NonFinite { name })
    }
}
