//! The minimum-energy input over `N` samples: the shared linear algebra of
//! the minimum-energy, bisection and profile planners (below all three).
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

use crate::linalg::{
    Matrix, Vector, accumulate_outer, at, at2, dot, mat_vec, spd_solve_scaled, vec_add, vec_sub,
};
use crate::model::Discrete;

/// Pivot-ratio floor below which the scaled Gramian is treated as singular
/// (target not reachable in that many samples).
const REACH_RATIO: f64 = 1e-15;
/// Relative landing residual (in the Gramian's scaled coordinates) accepted
/// after refinement.
const REACH_RESIDUAL: f64 = 1e-9;
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
