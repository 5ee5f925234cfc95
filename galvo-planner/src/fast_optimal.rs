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
//! stays far inside the acceptance bounds; the stepper lands exactly on the
//! planned target at the end of every move in any case.

use crate::error::Error;
use crate::jump::{InputLaw, JumpPlan, MethodKind, PlanInfo};
use crate::linalg::at;
use crate::model::{Discrete, LinearModel, ModelKind};
use crate::optimal::{
    BangBang, ContinuousOptimum, OptimalInfo, OptimalStructure, RigidMove, plan_time_optimal,
    rigid_move,
};

/// `e^z − 1` for `z ≤ 0.5` in `f32`, a few ulp: Taylor series near 0,
/// `2^k·e^r − 1` with `|r| ≤ ln2/2` otherwise. No `f64`, no libm.
pub(crate) fn expm1_f32(z: f32) -> f32 {
    if z.is_nan() {
        return z;
    }
    if z < -88.0 {
        return -1.0;
    }
    let series = |r: f32| -> f32 {
        // r + r²/2! + … + r⁹/9! (Horner); |r| ≤ 0.35: last term < 2e-11.
        let mut p = 1.0 / 362_880.0;
        p = p * r + 1.0 / 40_320.0;
        p = p * r + 1.0 / 5_040.0;
        p = p * r + 1.0 / 720.0;
        p = p * r + 1.0 / 120.0;
        p = p * r + 1.0 / 24.0;
        p = p * r + 1.0 / 6.0;
        p = p * r + 0.5;
        p = p * r + 1.0;
        p * r
    };
    if z > -0.35 && z < 0.35 {
        return series(z);
    }
    // z = k·ln2 + r, ln2 split in a high part exact in f32 and a low part.
    const LN2_HI: f32 = 0.693_145_75;
    const LN2_LO: f32 = 1.428_606_8e-6;
    const INV_LN2: f32 = core::f32::consts::LOG2_E;
    let kf = z * INV_LN2;
    // Round to nearest without libm (|kf| < 128).
    let k = if kf < 0.0 {
        (kf - 0.5) as i32
    } else {
        (kf + 0.5) as i32
    };
    let kf = k as f32;
    let r = (z - kf * LN2_HI) - kf * LN2_LO;
    let er = series(r) + 1.0;
    if k < -126 {
        return -1.0;
    }
    let scale = f32::from_bits(((k + 127) as u32) << 23);
    er * scale - 1.0
}

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

/// The larger of `a` and `b` (plain compare: `f32::max` is a library call
/// on the M4F); `b` when `a` is NaN.
#[inline(always)]
fn hi(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// The smaller of `a` and `b`; `b` when `a` is NaN.
#[inline(always)]
fn lo(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
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

/// One decaying mode of the sampled model: `λ = e^ℓ`, `ℓ = p·Ts < 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Mode {
    ell: f32,
    /// `λ − 1`.
    mu: f32,
}

impl Mode {
    /// `(G(x), λ^⌊x⌋)` for `x ≥ 0`.
    #[inline]
    fn g(&self, x: f32) -> (f32, f32) {
        let mut cache = PowerCache::EMPTY;
        self.g_cached(x, &mut cache)
    }

    /// [`g`](Self::g) reusing `λ^n − 1` when `x` is still in sample `n`
    /// (Newton's last steps stay in the same samples).
    #[inline]
    fn g_cached(&self, x: f32, cache: &mut PowerCache) -> (f32, f32) {
        let cell = x as i32; // x ≥ 0: truncation is floor
        let n = cell as f32;
        let f = x - n;
        let m = if cache.cell == cell {
            cache.pm1
        } else {
            let m = expm1_f32(n * self.ell);
            *cache = PowerCache { cell, pm1: m };
            m
        };
        (m / self.mu + f * (1.0 + m), 1.0 + m)
    }
}

/// `λ^n − 1` of the last sample `n` a point was in.
#[derive(Debug, Clone, Copy)]
struct PowerCache {
    cell: i32,
    pm1: f32,
}

impl PowerCache {
    const EMPTY: Self = Self { cell: -1, pm1: 0.0 };
}

/// The sampled bang-bang in reversed switch points, units of `Umax`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Switches {
    sigma1: f32,
    sigma2: f32,
}

/// How far (samples) a converged switch may sit outside the sample it was
/// solved in: rounding only.
const CELL_TOL: f32 = 1e-3;

#[cfg(test)]
extern crate std;
#[cfg(test)]
std::thread_local! {
    /// Newton iterations (tests count them).
    pub(crate) static ITERATIONS: core::cell::Cell<u32> = const { core::cell::Cell::new(0) };
}

/// Newton iterations per solve (piecewise linear: exact after the switch
/// samples settle; 2–5 in practice).
const MAX_NEWTON: u32 = 24;

/// Solves the two modal equations for `(σ1, σ2)`. `n_of` gives `N` (and
/// `dN/dσ1 = −dN/dσ2`) for the current switches: either fixed or from the
/// integrator equation with `v = Umax`. Returns `None` when Newton does not
/// settle or the solution leaves `1 ≤ σ2 ≤ σ1 ≤ N`.
fn newton(modes: &[Mode; 2], m: f32, fixed_n: Option<f32>, mut s: Switches) -> Option<Switches> {
    // With v = Umax the last sample is part of the third arc (σ2 ≥ 0);
    // with a free last sample the third arc starts before it (σ2 ≥ 1).
    let s2_min = if fixed_n.is_some() { 1.0 } else { 0.0 };
    // G(N) once when N is fixed.
    let [ma, mb] = modes;
    let g_fixed = fixed_n.map_or([(0.0, 0.0); 2], |n| [ma.g(n), mb.g(n)]);
    let mut last_cells = (-1i32, -1i32, -1i32);
    let mut caches = [[PowerCache::EMPTY; 3]; 2];
    for _it in 0..MAX_NEWTON {
        #[cfg(test)]
        ITERATIONS.with(|c| c.set(c.get() + if fixed_n.is_some() { 100 } else { 1 }));
        // N and its derivative wrt σ1 (−that wrt σ2).
        let (n, dn) = match fixed_n {
            Some(n) => (n, 0.0),
            None => (m + 2.0 * s.sigma1 - 2.0 * s.sigma2, 2.0),
        };
        if !(n.is_finite() && n >= 1.0) {
            return None;
        }
        // Residual of mode i with v eliminated by the integrator equation:
        // fixed N: (M − N + 2σ1 − 2σ2) + Gi(N) − 2Gi(σ1) + 2Gi(σ2);
        // free N (v = Umax): Gi(N) − 2Gi(σ1) + 2Gi(σ2).
        // Split into integer and fractional parts so that long moves keep
        // the precision of M (the integers are exact in f32).
        let base = match fixed_n {
            Some(n) => {
                let (n1, n2) = ((s.sigma1 as i32) as f32, (s.sigma2 as i32) as f32);
                (m - (n - 2.0 * n1 + 2.0 * n2)) + 2.0 * ((s.sigma1 - n1) - (s.sigma2 - n2))
            }
            None => 0.0,
        };
        let dbase = if fixed_n.is_some() { 2.0 } else { 0.0 };
        let mut r = [0.0f32; 2];
        let mut jac = [[0.0f32; 2]; 2];
        for ((i, mode), cache) in modes.iter().enumerate().zip(caches.iter_mut()) {
            let [c_n, c_1, c_2] = cache;
            let (gn, ln) = match (fixed_n, g_fixed.get(i)) {
                (Some(_), Some(g)) => *g,
                _ => mode.g_cached(n, c_n),
            };
            let (g1, l1) = mode.g_cached(s.sigma1, c_1);
            let (g2, l2) = mode.g_cached(s.sigma2, c_2);
            if let (Some(ri), Some(row)) = (r.get_mut(i), jac.get_mut(i)) {
                *ri = base + gn - 2.0 * g1 + 2.0 * g2;
                *row = [dbase + ln * dn - 2.0 * l1, -dbase - ln * dn + 2.0 * l2];
            }
        }
        let cells = (n as i32, s.sigma1 as i32, s.sigma2 as i32);
        let [[mut a, mut b], [mut c, mut d]] = jac;
        let mut det = a * d - b * c;
        let exact_jacobian = det != 0.0;
        if det == 0.0 {
            // Two of N, σ1, σ2 share a sample (the piecewise-linear
            // Jacobian is singular there): step with the slopes of the
            // continuous-time weights e^{ℓx} instead, which differ.
            let slope = |mode: &Mode, x: f32| 1.0 + expm1_f32(x * mode.ell);
            let row = |mode: &Mode| {
                let (ln, l1, l2) = (slope(mode, n), slope(mode, s.sigma1), slope(mode, s.sigma2));
                [dbase + ln * dn - 2.0 * l1, -dbase - ln * dn + 2.0 * l2]
            };
            [a, b] = row(ma);
            [c, d] = row(mb);
            det = a * d - b * c;
        }
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let [r0, r1] = r;
        let d1 = -(d * r0 - b * r1) / det;
        let d2 = -(a * r1 - c * r0) / det;
        if (exact_jacobian && fixed_n.is_none()) || cells == last_cells {
            // Within the current switch samples the equations are linear:
            // a step with their Jacobian is the exact solution if it stays
            // in those samples (a rounding-size overshoot of a cell edge is
            // allowed). With N fixed (the plan itself) one more step is
            // taken in the final samples: it refines the f32 rounding.
            let out = Switches {
                sigma1: s.sigma1 + d1,
                sigma2: s.sigma2 + d2,
            };
            let n_out = fixed_n.unwrap_or(m + 2.0 * out.sigma1 - 2.0 * out.sigma2);
            let inside = |x: f32, c: i32| {
                let lo = c as f32;
                x >= lo - CELL_TOL && x <= lo + 1.0 + CELL_TOL
            };
            if inside(out.sigma1, cells.1) && inside(out.sigma2, cells.2) && inside(n_out, cells.0)
            {
                return valid(out, n_out, s2_min);
            }
        }
        last_cells = cells;
        // Damped: at most a quarter of the move per step.
        let cap = 0.25 * hi(n, 4.0);
        let lim = |x: f32| lo(hi(x, -cap), cap);
        let mut s1 = s.sigma1 + lim(d1);
        let mut s2 = s.sigma2 + lim(d2);
        // Project onto 1 ≤ σ2 ≤ σ1 (≤ N when N is fixed).
        if let Some(n) = fixed_n {
            s1 = lo(s1, n);
        }
        s2 = hi(s2, s2_min);
        s1 = hi(s1, s2);
        if !(s1.is_finite() && s2.is_finite()) {
            return None;
        }
        s = Switches {
            sigma1: s1,
            sigma2: s2,
        };
    }
    None
}

fn valid(s: Switches, n: f32, s2_min: f32) -> Option<Switches> {
    let tol = 1e-4;
    if s.sigma1.is_finite()
        && s.sigma2.is_finite()
        && s.sigma2 >= s2_min - tol
        && s.sigma1 >= s.sigma2 - tol
        && s.sigma1 <= n + tol
    {
        let sigma2 = hi(s.sigma2, s2_min);
        let sigma1 = lo(hi(s.sigma1, sigma2), n);
        Some(Switches { sigma1, sigma2 })
    } else {
        None
    }
}

/// Smallest `|p·Ts|` of a mode the `f32` form handles: the rounding of the
/// mode sums grows as `ε/|ℓ|` (≈ 5e-6 of the speed and current scales at
/// this limit), and a mode that decays over hundreds of samples is nearly
/// a second integrator. The reference galvo has |ℓ| = 0.029 at Ts = 10 µs.
const MIN_ABS_ELL: f32 = 3.0e-3;

/// Largest estimated relative landing error (θ, of the move) accepted
/// from the `f32` solution (see [`fast_plan`]); the reference galvo at
/// Ts = 10 µs stays below 2.5e-4 down to one-sample moves.
const MAX_REL_LANDING_ERROR: f32 = 1e-3;

/// Longest move (samples) planned in `f32`; longer ones use `f64`.
const MAX_F32_SAMPLES: f32 = 1024.0;

/// What the `f32` planner needs of a sampled rigid model, computed once
/// when the model is discretised (part of [`Discrete`]): the two decaying
/// modes and the integrator gain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RigidModes {
    modes: [Mode; 2],
    /// `Kt/(Ts·Umax)`: `M = D·m_per_rad` in samples of `Umax`.
    m_per_rad: f32,
    u_max_v: f32,
    ts_s: f32,
}

impl RigidModes {
    /// `None` when the model is not rigid, its electrical poles are complex
    /// or too close for the modal form in `f32`, or a mode is too slow.
    pub(crate) fn new<const S: usize>(model: &LinearModel<S>, ts_s: f64) -> Option<Self> {
        if S != 3 || model.kind() != ModelKind::Rigid {
            return None;
        }
        let a = model.a();
        let get = |i: usize, j: usize| a.get(i).map_or(0.0, |row| at(row, j));
        // ω' = (Kt/J)·I, I' = −(Kt/L)·ω − (R/L)·I.
        let alpha = -(get(2, 2) as f32);
        let beta = -(get(1, 2) as f32) * (get(2, 1) as f32);
        let ts = ts_s as f32;
        let disc2 = alpha * alpha - 4.0 * beta;
        if !(alpha > 0.0 && beta > 0.0 && disc2 > 1e-2 * alpha * alpha) {
            return None;
        }
        let q = -0.5 * (alpha + libm::sqrtf(disc2));
        let (p1, p2) = (q, beta / q);
        let mode = |p: f32| {
            let ell = p * ts;
            Mode {
                ell,
                mu: expm1_f32(ell),
            }
        };
        let modes = [mode(p2), mode(p1)];
        let m_per_rad = (model.drive().kt_nm_per_a / (ts_s * model.u_max_v())) as f32;
        let ok = modes
            .iter()
            .all(|m| m.ell < -MIN_ABS_ELL && m.ell > -80.0 && m.mu < 0.0)
            && m_per_rad.is_finite()
            && m_per_rad > 0.0;
        ok.then_some(Self {
            modes,
            m_per_rad,
            u_max_v: model.u_max_v() as f32,
            ts_s: ts,
        })
    }
}

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
        let (l1, l2) = (1.0 + m1.mu, 1.0 + m2.mu);
        let k = m * u_max / (m1.mu * m2.mu);
        let u = [k * l1 * l2, -k * (l1 + l2), k];
        if u.iter().all(|x| x.abs() <= u_max) {
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
    let first = libm::ceilf(n_star - 5e-3);
    let first = if first.is_finite() && first >= 1.0 {
        first as usize
    } else {
        1
    };
    let mut guess = cont.unwrap_or(guess);
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
    let (d, sign) = if delta < 0.0 {
        (-delta, -1.0)
    } else {
        (delta, 1.0)
    };
    let Some(fast) = disc.rigid_modes() else {
        return plan_time_optimal(disc, from_rad, to_rad, capacity);
    };
    let modes = fast.modes;
    let u_max = disc.u_max_v();
    let u_max32 = fast.u_max_v;
    // M = S0/Umax = D·Kt/(Ts·Umax), samples.
    let m = (d as f32) * fast.m_per_rad;
    if !(m.is_finite() && m > 0.0) || m > 1.0e6 {
        return plan_time_optimal(disc, from_rad, to_rad, capacity);
    }
    let Some(sol) = fast_plan(&modes, m, u_max32, capacity)? else {
        return plan_time_optimal(disc, from_rad, to_rad, capacity);
    };
    let ts = fast.ts_s;
    let continuous = sol.cont.map(|s| ContinuousOptimum {
        time_s: f64::from(sol.n_star * ts),
        switches_s: (
            f64::from((sol.n_star - s.sigma1) * ts),
            f64::from((sol.n_star - s.sigma2) * ts),
        ),
    });
    let samples_lower_bound = if continuous.is_some() {
        let c = libm::ceilf(sol.n_star - 1e-4);
        if c >= 1.0 { c as usize } else { 1 }
    } else {
        0
    };
    let mut info = OptimalInfo {
        structure: OptimalStructure::BangBang,
        continuous,
        samples_lower_bound,
        switch_samples: (0.0, 0.0),
        last_sample_v: 0.0,
        single_precision: true,
    };
    let n = sol.n;
    match sol.kind {
        FastKind::DeadBeat(u) => {
            info.structure = OptimalStructure::DeadBeat;
            let u64: [f64; 3] =
                core::array::from_fn(|j| sign * f64::from(*u.get(2 - j).unwrap_or(&0.0)));
            let peak = u.iter().fold(0.0f32, |p, x| hi(p, x.abs()));
            Ok(JumpPlan::with_peak(
                disc,
                z0,
                z1,
                3,
                InputLaw::Explicit3 { u_v: u64 },
                MethodKind::TimeOptimal,
                PlanInfo::Optimal(info),
                f64::from(peak),
            ))
        }
        FastKind::BangBang(s, w) => {
            let nf = n as f64;
            let s1 = nf - f64::from(s.sigma1);
            let s2 = nf - f64::from(s.sigma2);
            let v = f64::from(w) * u_max;
            info.switch_samples = (s1, s2);
            info.last_sample_v = sign * v;
            let law = BangBang::new(n, s1, s2, v, u_max, sign);
            let peak = law.peak_abs_u_v();
            Ok(JumpPlan::with_peak(
                disc,
                z0,
                z1,
                n,
                InputLaw::BangBang(law),
                MethodKind::TimeOptimal,
                PlanInfo::Optimal(info),
                peak,
            ))
        }
    }
}

#[cfg(test)]
mod tests;
