//! Time-optimal rest-to-rest planning for the rigid model in single
//! precision: microseconds on the Cortex-M4F (its FPU is `f32` only).
//!
//! Same plan as [`optimal::plan_time_optimal`](crate::optimal::plan_time_optimal)
//! (sampled `+,−,+` bang-bang with fractional switch samples and a free
//! last sample, or the 3-sample dead-beat input for tiny moves), found in
//! modal coordinates instead of by continuation in the distance.
//!
//! # Method
//!
//! The sampled rigid model has the eigenvalues 1, λ1 = e^{p1·Ts} and
//! λ2 = e^{p2·Ts}. Writing the input with the sample index reversed
//! (`j = N−1−k`), a rest-to-rest move of `D` in `N` samples is exactly
//!
//! * `Σ_j u_j = S0 = D·Kt/Ts` (integrator mode: `Kt·Δθ = ∫U dt`), and
//! * `Σ_j u_j·λi^j = 0` for i = 1, 2 (both decaying modes at rest).
//!
//! For the sampled bang-bang with reversed switch points `σ1 ≥ σ2 ≥ 1`
//! (samples from the end) and last sample `v`, the sums are
//! `v + U·(N − 2σ1 + 2σ2 − 1)` and `v + U·(Gi(N) − 2Gi(σ1) + 2Gi(σ2) − 1)`
//! with the cumulative weight `G(x) = (λ^n − 1)/(λ − 1) + f·λ^n`
//! (`x = n + f`): piecewise linear in the switch points, so Newton's
//! method on `(σ1, σ2)` is exact once the switch samples are right.
//!
//! 1. The shortest real-valued `N*` with `v = Umax` (the continuous-time
//!    optimum in samples is its lower bound) by Newton on two unknowns
//!    (the integrator equation gives `N` in closed form), started from the
//!    longer of the jerk-limited (`σ2 = N/4, σ1 = 3N/4`) and the
//!    current-limited estimates.
//! 2. `N = ⌈N*⌉`: `(σ1, σ2)` by the same Newton with `N` fixed, `v` from
//!    the integrator equation; the first `N` with `|v| ≤ Umax` is the plan.
//!
//! Every power is `λ^x − 1 = expm1(x·p·Ts)` by a small `f32` routine
//! (accurate to a few ulp, no `f64`), so a plan costs two small Newton
//! solves of a few iterations each. Galvos this does not cover (complex or
//! nearly coincident electrical poles) and the rare case where Newton does
//! not settle fall back to the `f64` planner: slower, same guarantees.
//!
//! The landing error of the `f32` solution (checked in `f64` simulation)
//! stays far inside the acceptance bounds; the integrator lands exactly on the
//! planned target at the end of every move in any case.

mod newton;

use crate::bang_bang::{FastLaw, FastMove, FastShape};
use crate::error::Error;
use crate::model::Discrete;
use crate::optimal::{RigidMove, plan_time_optimal, rigid_move};
use crate::plan::JumpPlan;
use crate::rigid_modes::{Mode, hi, lo};
#[cfg(test)]
pub(crate) use newton::ITERATIONS;
use newton::{Switches, newton};

/// `∛x` for `x > 0` in `f32` (libm's `cbrtf` computes in `f64`): exponent
/// third by bit manipulation, then Newton steps.
fn cbrt_f32(x: f32) -> f32 {
    if !(x > 0.0 && x.is_finite()) {
        return 0.0;
    }
    let mut y = f32::from_bits(x.to_bits() / 3 + 709_921_077);
    for _ in 0..4 {
        y -= (y - x / (y * y)) * (1.0 / 3.0);
    }
    y
}

/// `√x` for `x ≥ 0` to ~1e-5 (initial guesses only; libm's `sqrtf` is a
/// software routine on the M4F): exponent halved by bit manipulation, then
/// three Newton steps.
fn sqrt_f32(x: f32) -> f32 {
    if !(x > 0.0 && x.is_finite()) {
        return 0.0;
    }
    let mut y = f32::from_bits((x.to_bits() >> 1) + 0x1fbd_1df5);
    for _ in 0..3 {
        y = 0.5 * (y + x / y);
    }
    y
}

/// Largest estimated relative landing error (θ, of the move) accepted
/// from the `f32` solution (see [`fast_plan`]); the reference galvo at
/// Ts = 10 µs stays below 2.5e-4 down to one-sample moves.
const MAX_REL_LANDING_ERROR: f32 = 1e-3;

/// Longest move (samples) planned in `f32`; longer ones use `f64`.
const MAX_F32_SAMPLES: f32 = 1024.0;

/// What [`fast_plan`] found.
struct FastSolution {
    n: usize,
    /// Dead-beat inputs (reversed: j = 0 is the last sample), V, or the
    /// bang-bang switches and last-sample value `v/Umax`.
    kind: FastKind,
    n_star: f32,
    cont: Option<Switches>,
}

enum FastKind {
    DeadBeat([f32; 3]),
    BangBang(Switches, f32),
}

/// The `f32` search. `m = S0/Umax` (samples), `u_max` in V.
fn fast_plan(
    modes: &[Mode; 2],
    m: f32,
    u_max: f32,
    capacity: usize,
) -> Result<Option<FastSolution>, Error> {
    let [m1, m2] = modes;
    // Start: the triple integrator (jerk-limited) move, `D = jerk·T³/32`,
    // switches at T/4 and 3T/4; in modal sample units `N³ = 32·M/(ℓ1·ℓ2)`.
    let n_tri = cbrt_f32(32.0 * m / (m1.ell * m2.ell));
    // Longer moves are current-limited: a double integrator with the
    // acceleration Kt·Umax/(R·J), `N = 2·√(M·τm/Ts)` (τm/Ts = |ℓ1+ℓ2|/(ℓ1·ℓ2)),
    // plus the electrical lag ≈ 0.4·L/(R·Ts) = 0.4/|ℓ1+ℓ2|. The third arc
    // tends to T/4 (jerk-limited) or ≈ L/(R·Ts) (current-limited), and
    // `N = M + 2·(σ1 − σ2)` fixes σ1. Only the start of Newton's method.
    let sum = (m1.ell + m2.ell).abs();
    let n_cur = 2.0 * sqrt_f32(m * sum / (m1.ell * m2.ell)) + 0.4 / sum;
    let n0 = hi(n_tri, n_cur);
    let sigma2 = 1.0 / (4.0 / n0 + sum);
    let guess = Switches {
        sigma1: sigma2 + 0.5 * hi(n0 - m, 0.0),
        sigma2,
    };
    // Tiny moves: the unique 3-sample (dead-beat) input, optimal whenever
    // it is within Umax (fewer than 3 samples cannot land 3 states).
    if n_tri < 4.0 {
        if 3 > capacity {
            return Err(Error::CapacityExceeded {
                needed: 3,
                capacity,
            });
        }
        if let Some(u) = dead_beat(modes, m, u_max) {
            return Ok(Some(FastSolution {
                n: 3,
                kind: FastKind::DeadBeat(u),
                n_star: n_tri,
                cont: None,
            }));
        }
    }
    let cont = newton(modes, m, None, guess);
    let n_star = cont.map_or(n_tri, |s| m + 2.0 * s.sigma1 - 2.0 * s.sigma2);
    // Precision of f32: the mode equations are sums of ±Umax over N
    // samples whose net is M, so their rounding, mapped back to θ through
    // the modal coupling (≈ (|ℓ1|+|ℓ2|)/|ℓ1−ℓ2|), is ≈ 2·ε·(N/M)·coupling
    // of the move. Long moves, moves short against the electrical modes and
    // nearly coincident modes that would land worse go to the f64 planner.
    let coupling = (m1.ell.abs() + m2.ell.abs()) / (m1.ell - m2.ell).abs();
    let rel_err = 2.0 * f32::EPSILON * (n_star / m) * coupling;
    // (NaN compares false: falls back.)
    let in_range = n_star <= MAX_F32_SAMPLES && (n_star <= 3.5 || rel_err <= MAX_REL_LANDING_ERROR);
    if !in_range {
        return Ok(None);
    }
    let guess = cont.unwrap_or(guess);
    fixed_n_search(modes, m, n_star, guess, cont, capacity)
}

/// The unique 3-sample (dead-beat) input for `m` (samples of `Umax`),
/// reversed (j = 0 is the last sample), V; `None` when it exceeds Umax.
#[inline(always)]
fn dead_beat(modes: &[Mode; 2], m: f32, u_max: f32) -> Option<[f32; 3]> {
    let [m1, m2] = modes;
    let (l1, l2) = (1.0 + m1.mu, 1.0 + m2.mu);
    let k = m * u_max / (m1.mu * m2.mu);
    let u = [k * l1 * l2, -k * (l1 + l2), k];
    u.iter().all(|x| x.abs() <= u_max).then_some(u)
}

/// The plan itself: the first whole sample count from `⌈N*⌉` (at least 4)
/// whose switches, solved with `N` fixed from `guess` stretched along,
/// leave a last sample within Umax (4 counts are tried).
#[inline(always)]
fn fixed_n_search(
    modes: &[Mode; 2],
    m: f32,
    n_star: f32,
    mut guess: Switches,
    cont: Option<Switches>,
    capacity: usize,
) -> Result<Option<FastSolution>, Error> {
    let first = libm::ceilf(n_star - 5e-3);
    let first = if first.is_finite() && first >= 1.0 {
        first as usize
    } else {
        1
    };
    guess.sigma2 = hi(guess.sigma2, 1.0);
    guess.sigma1 = hi(guess.sigma1, guess.sigma2);
    let first = first.max(4);
    let mut prev_n = hi(n_star, 1.0);
    for n in first..first + 4 {
        if n > capacity {
            return Err(Error::CapacityExceeded {
                needed: n,
                capacity,
            });
        }
        let nf = n as f32;
        // Stretch the previous switches to the new length.
        let stretch = nf / prev_n;
        guess.sigma1 = lo(guess.sigma1 * stretch, nf);
        guess.sigma2 = lo(hi(guess.sigma2 * stretch, 1.0), guess.sigma1);
        prev_n = nf;
        let Some(s) = newton(modes, m, Some(nf), guess) else {
            continue;
        };
        let (n1, n2) = ((s.sigma1 as i32) as f32, (s.sigma2 as i32) as f32);
        let w = (m - (nf - 2.0 * n1 + 2.0 * n2 - 1.0)) + 2.0 * ((s.sigma1 - n1) - (s.sigma2 - n2));
        if w.abs() <= 1.0 {
            return Ok(Some(FastSolution {
                n,
                kind: FastKind::BangBang(s, w),
                n_star,
                cont,
            }));
        }
        guess = s;
    }
    Ok(None)
}

/// Time-optimal rest-to-rest move from `from_rad` to `to_rad` (rigid model
/// only), planned in `f32` (see the module documentation). Falls back to
/// [`plan_time_optimal`] where the `f32` modal form does not apply.
pub fn plan_time_optimal_fast<const S: usize>(
    disc: &Discrete<S>,
    from_rad: f64,
    to_rad: f64,
    capacity: usize,
) -> Result<JumpPlan<S>, Error> {
    match solve(disc, from_rad, to_rad, capacity)? {
        Ok(mv) => Ok(JumpPlan::fast(disc, mv)),
        Err(_) => plan_time_optimal(disc, from_rad, to_rad, capacity),
    }
}

/// [`plan_time_optimal_fast`] without its `f64` fallback, for a CPU with
/// a single-precision FPU only (the M4F, where the `f64` planner takes
/// milliseconds): the same plan where the `f32` modal form applies, else
/// [`Error::UnsupportedModel`] (no rigid modal form) or
/// [`Error::NoConvergence`] (the `f32` solve found no plan). A caller
/// that uses only this links none of the `f64` time-optimal planner.
pub fn plan_time_optimal_f32<const S: usize>(
    disc: &Discrete<S>,
    from_rad: f64,
    to_rad: f64,
    capacity: usize,
) -> Result<JumpPlan<S>, Error> {
    solve_f32(disc, from_rad, to_rad, capacity).map(|mv| JumpPlan::fast(disc, mv))
}

/// The move [`plan_time_optimal_f32`] plans, solved but not yet written
/// into a plan (a few words: the two-axis planner writes both plans in
/// place once both axes are solved).
#[inline(always)]
pub(crate) fn solve_f32<const S: usize>(
    disc: &Discrete<S>,
    from_rad: f64,
    to_rad: f64,
    capacity: usize,
) -> Result<FastMove, Error> {
    solve(disc, from_rad, to_rad, capacity)?
}

/// The `f32` solution, `Ok(Err(why))` where the `f32` form does not
/// apply (the fallback's cue), `Err` for bad input.
#[inline(always)]
fn solve<const S: usize>(
    disc: &Discrete<S>,
    from_rad: f64,
    to_rad: f64,
    capacity: usize,
) -> Result<Result<FastMove, Error>, Error> {
    let RigidMove::Move {
        from_rad,
        to_rad,
        capacity,
        ..
    } = rigid_move(disc, from_rad, to_rad, capacity)?
    else {
        return Ok(Ok(FastMove {
            from_rad,
            to_rad: from_rad,
            law: None,
        }));
    };
    let delta = to_rad - from_rad;
    let (d, negative) = if delta < 0.0 {
        (-delta, true)
    } else {
        (delta, false)
    };
    let Some(fast) = disc.rigid_modes() else {
        return Ok(Err(Error::UnsupportedModel));
    };
    let modes = fast.modes;
    // M = S0/Umax = D·Kt/(Ts·Umax), samples.
    let m = (d as f32) * fast.m_per_rad;
    if !(m.is_finite() && m > 0.0) || m > 1.0e6 {
        return Ok(Err(Error::NoConvergence));
    }
    let Some(sol) = fast_plan(&modes, m, fast.u_max_v, capacity)? else {
        return Ok(Err(Error::NoConvergence));
    };
    let shape = match sol.kind {
        FastKind::DeadBeat(u) => FastShape::DeadBeat(u),
        FastKind::BangBang(s, w) => FastShape::BangBang {
            sigma1: s.sigma1,
            sigma2: s.sigma2,
            w,
        },
    };
    Ok(Ok(FastMove {
        from_rad,
        to_rad,
        law: Some(FastLaw {
            n: sol.n,
            negative,
            n_star: sol.n_star,
            cont: sol.cont.map(|s| (s.sigma1, s.sigma2)),
            ts_s: fast.ts_s,
            shape,
        }),
    }))
}

#[cfg(test)]
mod tests;
