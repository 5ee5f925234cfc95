//! Time-optimal rest-to-rest planner for the rigid model, in `f64`.
//!
//! [`Method::TimeOptimal`](crate::jump::Method::TimeOptimal) plans with the
//! single-precision [`fast_optimal`](crate::fast_optimal) planner (same
//! plans, microseconds on the M4F); this one is its reference and its
//! fallback for the galvos the `f32` form does not cover.
//!
//! The rigid model has the eigenvalues 0, p1, p2 (real and negative for the
//! reference galvo: −2.9e3 and −12.7e3 1/s). For real eigenvalues the
//! continuous-time minimum-time control under `|U| ≤ Umax` is bang-bang with
//! at most two switches (Feldbaum): `+Umax` on `[0, t1)`, `−Umax` on
//! `[t1, t2)`, `+Umax` on `[t2, T)` for a positive move. On the sample grid
//! the planner keeps that structure:
//!
//! 1. **Continuous optimum** `(t1, t2, T)` by Newton's method on the three
//!    landing equations `θ(T) = D, ω(T) = 0, I(T) = 0`, using the model's
//!    closed-form step response, with continuation in the distance (start in
//!    the jerk-limited regime where `t1 = T/4, t2 = 3T/4` is accurate and grow
//!    the distance ×16 per stage, smaller strides after a failed stage). `T` is a lower bound for every ZOH input,
//!    so `N ≥ ⌈T/Ts⌉`.
//! 2. **Sampled bang-bang** for `N = ⌈T/Ts⌉ − 1, ⌈T/Ts⌉, …`: every sample is
//!    the average of a `+,−,+` signal with switch points `s1 ≤ s2` (in
//!    samples) — saturated except the two samples containing a switch — and
//!    the last sample is a free value `v`. The three unknowns `(s1, s2, v)`
//!    are solved exactly for the discrete landing equations (piecewise
//!    linear; Newton converges in a few steps). The first `N` with
//!    `|v| ≤ Umax` is the plan: it lands exactly and never exceeds `Umax`
//!    by construction.
//!
//! When `⌈T/Ts⌉ ≤ 3` (tiny moves) the unique 3-sample (dead-beat) input is
//! tried first. For a strongly underdamped coil (complex poles) the optimum
//! may need more switches; when no two-switch solution exists the planner
//! falls back to the fastest minimum-energy input
//! ([`OptimalStructure::MinEnergyFallback`]), so a valid request still gets
//! an exact, feasible plan.
//!
//! Cost: the closed-form response makes every evaluation two `expm1` (real
//! poles) and a few dozen flops, no matrix exponential and no buffer; a
//! 20° move takes ~5 continuation stages of a few Newton steps plus 1–2
//! sampled solves (≈ 17–25 µs on a desktop core, see the README).

mod response;
mod search;

use crate::bang_bang::BangBang;
pub use crate::bang_bang::{ContinuousOptimum, OptimalInfo, OptimalStructure};
use crate::bisection::{BisectionConfig, plan_bisection};
use crate::error::Error;
use crate::gramian::{min_energy_at, samples_for};
use crate::linalg::{Matrix, Vector, at};
use crate::model::{Discrete, ModelKind};
use crate::plan::{InputLaw, JumpPlan, MethodKind, PlanInfo, effective_capacity};
use kinematics_core::numeric::finite;
use response::RigidResponse;
use search::{continuous_optimum, sampled_bang_bang};

/// Halvings of the minimum-energy fallback.
const FALLBACK_HALVINGS: u32 = 24;

/// A checked rest-to-rest move of the rigid model (both time-optimal
/// planners start here).
pub(crate) enum RigidMove<const S: usize> {
    /// Start and target are the same angle: hold.
    Hold,
    /// A move to plan.
    Move {
        /// Start angle, rad (finite).
        from_rad: f64,
        /// Target angle, rad (finite).
        to_rad: f64,
        /// Rest state at the start.
        z0: Vector<S>,
        /// Rest state at the target.
        z1: Vector<S>,
        /// Usable integrator capacity, samples.
        capacity: usize,
    },
}

/// Checks a time-optimal request: a rigid model, finite angles.
///
/// Errors: [`Error::UnsupportedModel`], [`Error::NonFinite`].
pub(crate) fn rigid_move<const S: usize>(
    disc: &Discrete<S>,
    from_rad: f64,
    to_rad: f64,
    capacity: usize,
) -> Result<RigidMove<S>, Error> {
    if S != 3 || disc.model().kind() != ModelKind::Rigid {
        return Err(Error::UnsupportedModel);
    }
    let from_rad = finite(from_rad, "from_rad")?;
    let to_rad = finite(to_rad, "to_rad")?;
    if from_rad == to_rad {
        return Ok(RigidMove::Hold);
    }
    let model = disc.model();
    Ok(RigidMove::Move {
        from_rad,
        to_rad,
        z0: model.rest_state(from_rad),
        z1: model.rest_state(to_rad),
        capacity: effective_capacity(capacity),
    })
}

/// How many sample counts above the continuous bound are tried.
const EXTRA_SAMPLE_COUNTS: usize = 12;

/// Time-optimal rest-to-rest move from `from_rad` to `to_rad` (rigid model
/// only). See the module documentation.
pub fn plan_time_optimal<const S: usize>(
    disc: &Discrete<S>,
    from_rad: f64,
    to_rad: f64,
    capacity: usize,
) -> Result<JumpPlan<S>, Error> {
    let RigidMove::Move {
        from_rad,
        to_rad,
        z0,
        z1,
        capacity,
    } = rigid_move(disc, from_rad, to_rad, capacity)?
    else {
        return Ok(JumpPlan::hold(disc, disc.model().rest_state(from_rad)));
    };
    let delta = to_rad - from_rad;
    let (d, sign) = (libm::fabs(delta), if delta < 0.0 { -1.0 } else { 1.0 });
    let u_max = disc.u_max_v();
    let ts = disc.ts_s();
    let drive = disc.model().drive();
    let resp = rigid_response(disc);
    let omega_scale = u_max / drive.kt_nm_per_a;
    let current_scale = u_max / drive.r_ohm;
    let jerk = drive.kt_nm_per_a * u_max / (drive.j_kg_m2 * drive.l_h);
    let tau_e = drive.l_h / drive.r_ohm;
    let cont = continuous_optimum(&resp, u_max, d, omega_scale, current_scale, jerk, tau_e);
    let n_lo = cont.map_or(1, |[_, _, t_c]| samples_for(t_c, ts).max(1));
    let mut info = OptimalInfo {
        structure: OptimalStructure::BangBang,
        continuous: cont.map(|[t1, t2, t_c]| ContinuousOptimum {
            time_s: t_c,
            switches_s: (t1, t2),
        }),
        samples_lower_bound: if cont.is_some() { n_lo } else { 0 },
        switch_samples: (0.0, 0.0),
        last_sample_v: 0.0,
        single_precision: false,
    };
    if n_lo <= S
        && let Some(plan) = dead_beat(disc, (z0, z1), capacity, &mut info)?
    {
        return Ok(plan);
    }
    if let Some([t1, t2, _]) = cont {
        let search = SampledSearch {
            resp: &resp,
            d,
            sign,
            scales: [d, omega_scale, current_scale],
            guess: (t1 / ts, t2 / ts),
        };
        if let Some(plan) = search.plan(disc, (z0, z1), n_lo, capacity, &mut info)? {
            return Ok(plan);
        }
    }
    // No two-switch solution: the fastest minimum-energy input instead.
    let cfg = BisectionConfig {
        p: FALLBACK_HALVINGS,
        bracket_s: None,
    };
    let plan = plan_bisection(disc, &z0, &z1, cfg, capacity)?;
    info.structure = OptimalStructure::MinEnergyFallback;
    Ok(plan.relabel(MethodKind::TimeOptimal, PlanInfo::Optimal(info)))
}

/// The `S`-sample (dead-beat) minimum-energy input, if it is within Umax.
fn dead_beat<const S: usize>(
    disc: &Discrete<S>,
    (z0, z1): (Vector<S>, Vector<S>),
    capacity: usize,
    info: &mut OptimalInfo,
) -> Result<Option<JumpPlan<S>>, Error> {
    if S > capacity {
        return Err(Error::CapacityExceeded {
            needed: S,
            capacity,
        });
    }
    match min_energy_at(disc, &z0, &z1, S, 2) {
        Some(sol) if sol.max_abs_u_v <= disc.u_max_v() => {
            info.structure = OptimalStructure::DeadBeat;
            let law = InputLaw::MinEnergy { lambda: sol.lambda };
            let info = PlanInfo::Optimal(*info);
            Ok(Some(JumpPlan::new(
                disc,
                z0,
                z1,
                S,
                law,
                MethodKind::TimeOptimal,
                info,
            )))
        }
        _ => Ok(None),
    }
}

/// The closed-form response of a rigid model (`S = 3`).
fn rigid_response<const S: usize>(disc: &Discrete<S>) -> RigidResponse {
    let model = disc.model();
    let drive = model.drive();
    let a3: Matrix<3, 3> = core::array::from_fn(|i| {
        core::array::from_fn(|j| model.a().get(i).map_or(0.0, |row| at(row, j)))
    });
    let b3: Vector<3> = core::array::from_fn(|i| at(model.b(), i));
    RigidResponse::new(
        drive.kt_nm_per_a,
        drive.j_kg_m2,
        drive.l_h,
        drive.r_ohm,
        a3,
        b3,
    )
}

/// The sampled bang-bang search over the sample counts above the
/// continuous bound, for a positive distance `d` (rad) moved in the
/// direction `sign`.
struct SampledSearch<'a> {
    resp: &'a RigidResponse,
    d: f64,
    sign: f64,
    /// Newton's residual scales (rad, rad/s, A).
    scales: Vector<3>,
    /// The continuous switches in samples, the start of every solve.
    guess: (f64, f64),
}

impl SampledSearch<'_> {
    /// The first sample count from `⌈T/Ts⌉ − 1` (at least `S + 1`) with a
    /// sampled bang-bang within Umax, as a plan; `None` when none of the
    /// [`EXTRA_SAMPLE_COUNTS`] tried has one.
    fn plan<const S: usize>(
        &self,
        disc: &Discrete<S>,
        (z0, z1): (Vector<S>, Vector<S>),
        n_lo: usize,
        capacity: usize,
        info: &mut OptimalInfo,
    ) -> Result<Option<JumpPlan<S>>, Error> {
        let (ts, u_max) = (disc.ts_s(), disc.u_max_v());
        let first = n_lo.saturating_sub(1).max(S + 1);
        for n in first..first.saturating_add(EXTRA_SAMPLE_COUNTS) {
            if n > capacity {
                return Err(Error::CapacityExceeded {
                    needed: n,
                    capacity,
                });
            }
            let solved =
                sampled_bang_bang(self.resp, ts, u_max, self.d, n, self.guess, self.scales);
            if let Some([s1, s2, v]) = solved {
                info.switch_samples = (s1, s2);
                info.last_sample_v = self.sign * v;
                let law = InputLaw::BangBang(BangBang::new(n, s1, s2, v, u_max, self.sign));
                let info = PlanInfo::Optimal(*info);
                return Ok(Some(JumpPlan::new(
                    disc,
                    z0,
                    z1,
                    n,
                    law,
                    MethodKind::TimeOptimal,
                    info,
                )));
            }
        }
        Ok(None)
    }
}

#[cfg(test)]
mod tests;
