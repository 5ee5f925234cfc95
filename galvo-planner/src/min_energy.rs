//! Minimum-energy inputs and the seed (patent) planner.
//!
//! Over `N` samples the final state is `Z(N) = Ad^N·Z0 + Γ·U` with
//! `Γ = [Ad^{N−1}Bd, …, Ad·Bd, Bd]`. The input of least energy `Σ u_k²` that
//! lands exactly on `Z1` is `U = Γᵀ·λ` with `W·λ = Z1 − Ad^N·Z0`, where
//! `W = Γ·Γᵀ = Σ_j Ad^j·Bd·Bdᵀ·Ad^jᵀ` is the reachability Gramian. So the
//! whole input sequence is described by the `S` numbers `λ`:
//! `u_k = (Ad^{N−1−k}·Bd)ᵀ·λ`.
//!
//! Numerics: `W`'s entries span many decades (rad vs rad/s vs A, and short
//! horizons make it nearly singular), so it is solved after symmetric
//! diagonal scaling with a pivoted elimination and refinement
//! ([`spd_solve_scaled`]); then the landing residual is recomputed by
//! superposition and corrected once more. Cost: O(N·S²) per evaluation,
//! no buffer.
//!
//! The seed planner (patent CN105005322B) bisects the move time `T` in
//! `[Tmin, Tmax]`: for each candidate it computes this input over
//! `N = ⌈T/Ts⌉` samples and checks `max|u_k| ≤ Umax`; too large → `T`
//! becomes the new `Tmin`, else the new `Tmax`; after `p` halvings the
//! bracket is `(Tmax − Tmin)/2^p` wide and the plan uses `Tmax`.

use crate::error::{Error, finite, positive};
use crate::jump::{
    InputLaw, JumpPlan, MAX_PLAN_SAMPLES, MethodKind, PlanInfo, effective_capacity, finite_state,
};
use crate::linalg::{Matrix, Vector, at, at2, dot, mat_vec, spd_solve_scaled, vec_add, vec_sub};
use crate::model::{Discrete, accumulate_outer};

/// Largest number of halvings carried out (beyond ~60 the bracket is below
/// the resolution of `f64` anyway).
pub const MAX_HALVINGS: u32 = 64;

/// Configuration of the seed planner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeedConfig {
    /// Number of halvings `p` (precision `(Tmax − Tmin)/2^p`).
    pub p: u32,
    /// Initial bracket `(Tmin, Tmax)` in seconds. `None`: `Tmax` is the first
    /// feasible time in `S·Ts, 2·S·Ts, 4·S·Ts, …` (at most the capacity) and
    /// `Tmin` the previous, infeasible one (0 if the first is feasible).
    pub bracket_s: Option<(f64, f64)>,
}

impl SeedConfig {
    /// `p = 8`, automatic bracket.
    pub const DEFAULT: Self = Self {
        p: 8,
        bracket_s: None,
    };
}

impl Default for SeedConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What the seed planner did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeedInfo {
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

/// Pivot-ratio floor below which the scaled Gramian is treated as singular
/// (target not reachable in that many samples).
const REACH_RATIO: f64 = 1e-15;
/// Relative landing residual (in the Gramian's scaled coordinates) accepted
/// after refinement.
const REACH_RESIDUAL: f64 = 1e-9;
/// Feasibility margin in the bisection, so that the final refinement cannot
/// push a feasible sequence over the limit.
const LIMIT_MARGIN: f64 = 1e-9;

/// A minimum-energy solution: `λ` and the peak |u|.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MinEnergySolution<const S: usize> {
    pub lambda: Vector<S>,
    pub max_abs_u_v: f64,
}

/// Gramian `W = Σ_{j<n} g_j g_jᵀ`, `g_j = Ad^j·Bd`.
pub(crate) fn gramian<const S: usize>(disc: &Discrete<S>, n: usize) -> Matrix<S, S> {
    let mut w = [[0.0; S]; S];
    let mut g = *disc.bd();
    for _ in 0..n {
        accumulate_outer(&mut w, &g);
        g = mat_vec(disc.ad(), &g);
    }
    w
}

/// Solves `W·λ = d` for an `n`-sample horizon (with `refinements` extra
/// superposition-residual corrections) and measures the peak |u|. `offset`
/// optionally adds a known input sequence `u⁰_k` (by k) whose effect is
/// already contained in `d`'s complement: `u_k = u⁰_k + g_{n−1−k}ᵀλ`.
/// Returns `None` when `d` is not reachable in `n` samples.
pub(crate) fn solve<const S: usize>(
    disc: &Discrete<S>,
    w: &Matrix<S, S>,
    d: &Vector<S>,
    n: usize,
    refinements: u32,
    offset: &dyn Fn(usize) -> f64,
) -> Option<MinEnergySolution<S>> {
    if n == 0 {
        return None;
    }
    let (mut lambda, ratio) = spd_solve_scaled(w, d)?;
    if ratio < REACH_RATIO {
        return None;
    }
    let mut refine_left = refinements;
    loop {
        // One pass: superposed final-state contribution and the peak |u|.
        let mut reached = [0.0; S];
        let mut peak = 0.0f64;
        let mut g = *disc.bd();
        for j in 0..n {
            let corr = dot(&g, &lambda);
            let u = offset(n - 1 - j) + corr;
            peak = peak.max(libm::fabs(u));
            for (r, gi) in reached.iter_mut().zip(g.iter()) {
                *r += gi * corr;
            }
            g = mat_vec(disc.ad(), &g);
        }
        let residual = vec_sub(d, &reached);
        // Residual relative to d in the scaled coordinates s_i = 1/√W_ii.
        let mut res_scaled = 0.0f64;
        let mut d_scaled = 0.0f64;
        for i in 0..S {
            let s = 1.0 / libm::sqrt(at2(w, i, i));
            res_scaled = res_scaled.max(libm::fabs(at(&residual, i)) * s);
            d_scaled = d_scaled.max(libm::fabs(at(d, i)) * s);
        }
        if refine_left == 0 {
            if res_scaled > REACH_RESIDUAL * d_scaled.max(f64::MIN_POSITIVE) || !peak.is_finite() {
                return None;
            }
            return Some(MinEnergySolution {
                lambda,
                max_abs_u_v: peak,
            });
        }
        refine_left -= 1;
        if let Some((dl, _)) = spd_solve_scaled(w, &residual) {
            lambda = vec_add(&lambda, &dl);
        }
    }
}

/// Minimum-energy input from `z0` to `z1` over exactly `n` samples. The plan
/// may exceed the voltage limit (see [`JumpPlan::within_voltage_limit`]).
/// Fails with [`Error::NotReachable`] when `z1` cannot be reached in `n`
/// samples (e.g. `n` smaller than the number of states).
pub fn plan_min_energy<const S: usize>(
    disc: &Discrete<S>,
    z0: &Vector<S>,
    z1: &Vector<S>,
    n: usize,
) -> Result<JumpPlan<S>, Error> {
    finite_state("start state", z0)?;
    finite_state("target state", z1)?;
    if z0 == z1 && n == 0 {
        return Ok(JumpPlan::hold(disc, *z0));
    }
    if n > MAX_PLAN_SAMPLES {
        return Err(Error::CapacityExceeded {
            needed: n,
            capacity: MAX_PLAN_SAMPLES,
        });
    }
    let sol = min_energy_at(disc, z0, z1, n, 2).ok_or(Error::NotReachable { samples: n })?;
    Ok(JumpPlan::new(
        disc,
        *z0,
        *z1,
        n,
        InputLaw::MinEnergy { lambda: sol.lambda },
        MethodKind::MinEnergy,
        PlanInfo::None,
    ))
}

/// λ and peak |u| of the minimum-energy input over `n` samples.
pub(crate) fn min_energy_at<const S: usize>(
    disc: &Discrete<S>,
    z0: &Vector<S>,
    z1: &Vector<S>,
    n: usize,
    refinements: u32,
) -> Option<MinEnergySolution<S>> {
    let (an, _) = disc.power(n);
    let d = vec_sub(z1, &mat_vec(&an, z0));
    let w = gramian(disc, n);
    solve(disc, &w, &d, n, refinements, &|_| 0.0)
}

/// Samples needed for a move time `t_s`: `⌈t/Ts⌉` (with a 1e-9 sample
/// tolerance against rounding), saturating.
pub(crate) fn samples_for(t_s: f64, ts_s: f64) -> usize {
    let x = libm::ceil(t_s / ts_s - 1e-9);
    if x <= 0.0 {
        0
    } else if x >= usize::MAX as f64 {
        usize::MAX
    } else {
        x as usize
    }
}

/// The seed planner: bisection on the move time with the minimum-energy
/// input. See the module documentation.
pub fn plan_seed<const S: usize>(
    disc: &Discrete<S>,
    z0: &Vector<S>,
    z1: &Vector<S>,
    cfg: SeedConfig,
    capacity: usize,
) -> Result<JumpPlan<S>, Error> {
    finite_state("start state", z0)?;
    finite_state("target state", z1)?;
    if z0 == z1 {
        return Ok(JumpPlan::hold(disc, *z0));
    }
    let capacity = effective_capacity(capacity);
    let ts = disc.ts_s();
    let limit = disc.u_max_v() * (1.0 - LIMIT_MARGIN);
    let mut evaluations = 0u32;
    let mut feasible = |n: usize| -> bool {
        evaluations += 1;
        n >= S && min_energy_at(disc, z0, z1, n, 0).is_some_and(|s| s.max_abs_u_v <= limit)
    };
    let (mut lo, mut hi) = match cfg.bracket_s {
        Some((t_min_s, t_max_s)) => {
            let t_min_s = finite("t_min_s", t_min_s)?;
            let t_max_s = positive("t_max_s", t_max_s)?;
            if t_min_s < 0.0 || t_min_s >= t_max_s {
                return Err(Error::InvalidBracket { t_min_s, t_max_s });
            }
            let n = samples_for(t_max_s, ts);
            if n > capacity {
                return Err(Error::CapacityExceeded {
                    needed: n,
                    capacity,
                });
            }
            if !feasible(n) {
                return Err(Error::InvalidBracket { t_min_s, t_max_s });
            }
            (t_min_s, t_max_s)
        }
        None => {
            let mut lo = 0.0;
            let mut hi = S as f64 * ts;
            loop {
                let n = samples_for(hi, ts);
                if n > capacity {
                    if capacity > samples_for(lo, ts) && feasible(capacity) {
                        hi = capacity as f64 * ts;
                        break;
                    }
                    return Err(Error::CapacityExceeded {
                        needed: capacity.saturating_add(1),
                        capacity,
                    });
                }
                if feasible(n) {
                    break;
                }
                lo = hi;
                hi *= 2.0;
            }
            (lo, hi)
        }
    };
    let initial = (lo, hi);
    let halvings = cfg.p.min(MAX_HALVINGS);
    for _ in 0..halvings {
        let mid = 0.5 * (lo + hi);
        if feasible(samples_for(mid, ts)) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    // Final input at Tmax, with refinement. Rounding in the refinement can
    // only move the peak by ~1e-12 relative; the margin above covers it, but
    // step on to the next sample count rather than ever exceed Umax.
    let mut n = samples_for(hi, ts);
    let mut tries = 0;
    let sol = loop {
        evaluations += 1;
        if n > capacity {
            return Err(Error::CapacityExceeded {
                needed: n,
                capacity,
            });
        }
        match min_energy_at(disc, z0, z1, n, 2) {
            Some(s) if s.max_abs_u_v <= disc.u_max_v() => break s,
            _ if tries < 4 => {
                n += 1;
                tries += 1;
            }
            _ => return Err(Error::NoConvergence),
        }
    };
    let info = SeedInfo {
        initial_bracket_s: initial,
        final_bracket_s: (lo, hi),
        halvings,
        evaluations,
    };
    Ok(JumpPlan::new(
        disc,
        *z0,
        *z1,
        n,
        InputLaw::MinEnergy { lambda: sol.lambda },
        MethodKind::Seed,
        PlanInfo::Seed(info),
    ))
}

#[cfg(test)]
mod tests;
