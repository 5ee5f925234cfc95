//! Newton's method on the two modal equations of the `f32` planner.

use crate::rigid_modes::{Mode, PowerCache, expm1_f32, hi, lo};

/// The sampled bang-bang in reversed switch points, units of `Umax`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Switches {
    pub(super) sigma1: f32,
    pub(super) sigma2: f32,
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

/// Iterations in the same switch samples, with the exact Jacobian, whose
/// full step leaves them, after which a solve gives up (see [`newton`]).
const PINNED_ITERATIONS: u32 = 2;

/// Solves the two modal equations for `(σ1, σ2)`. `n_of` gives `N` (and
/// `dN/dσ1 = −dN/dσ2`) for the current switches: either fixed or from the
/// integrator equation with `v = Umax`. Returns `None` when Newton does not
/// settle or the solution leaves `1 ≤ σ2 ≤ σ1 ≤ N`.
pub(super) fn newton(
    modes: &[Mode; 2],
    m: f32,
    fixed_n: Option<f32>,
    mut s: Switches,
) -> Option<Switches> {
    // With v = Umax the last sample is part of the third arc (σ2 ≥ 0);
    // with a free last sample the third arc starts before it (σ2 ≥ 1).
    let s2_min = if fixed_n.is_some() { 1.0 } else { 0.0 };
    // G(N) once when N is fixed.
    let [ma, mb] = modes;
    let g_fixed = fixed_n.map_or([(0.0, 0.0); 2], |n| [ma.g(n), mb.g(n)]);
    let mut last_cells = (-1i32, -1i32, -1i32);
    let mut pinned = 0u32;
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
        let dbase = if fixed_n.is_some() { 2.0 } else { 0.0 };
        let (r, jac) = modal_residual(modes, &mut caches, &g_fixed, m, fixed_n, (n, dn), s);
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
        let step = (-(d * r0 - b * r1) / det, -(a * r1 - c * r0) / det);
        if (exact_jacobian && fixed_n.is_none()) || cells == last_cells {
            // Within the current switch samples the equations are linear:
            // a step with their Jacobian is the exact solution if it stays
            // in those samples (a rounding-size overshoot of a cell edge is
            // allowed). With N fixed (the plan itself) one more step is
            // taken in the final samples: it refines the f32 rounding.
            if let Some((out, n_out)) = settled(s, step, m, fixed_n, cells) {
                return valid(out, n_out, s2_min);
            }
            if exact_jacobian && cells == last_cells {
                // The exact solution of these samples lies outside them and
                // the last step stayed in them: a bound (`σ2 ≥ 1`, `σ1 ≤ N`)
                // holds the switches there, and every further step is the
                // same projected step. This N has no plan; without this
                // exit the solve ran to MAX_NEWTON (a 1.34-LSB move: 26
                // iterations, 10 000 M4 instructions, for the same answer).
                pinned += 1;
                if pinned >= PINNED_ITERATIONS {
                    return None;
                }
            }
        }
        last_cells = cells;
        s = damped_step(s, step, n, fixed_n, s2_min)?;
    }
    None
}

/// Residuals of the two modal equations and their Jacobian in `(σ1, σ2)`
/// at the switches `s`, with `(N, dN/dσ1)`; `g_fixed` holds `Gi(N)` when
/// `N` is fixed.
#[inline(always)]
fn modal_residual(
    modes: &[Mode; 2],
    caches: &mut [[PowerCache; 3]; 2],
    g_fixed: &[(f32, f32); 2],
    m: f32,
    fixed_n: Option<f32>,
    (n, dn): (f32, f32),
    s: Switches,
) -> ([f32; 2], [[f32; 2]; 2]) {
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
    (r, jac)
}

/// The full Newton step `(d1, d2)` from `s` and its `N`, if they stay in
/// the samples `cells = (N, σ1, σ2)` they were solved in.
#[inline(always)]
fn settled(
    s: Switches,
    (d1, d2): (f32, f32),
    m: f32,
    fixed_n: Option<f32>,
    cells: (i32, i32, i32),
) -> Option<(Switches, f32)> {
    let out = Switches {
        sigma1: s.sigma1 + d1,
        sigma2: s.sigma2 + d2,
    };
    let n_out = fixed_n.unwrap_or(m + 2.0 * out.sigma1 - 2.0 * out.sigma2);
    let inside = |x: f32, c: i32| {
        let lo = c as f32;
        x >= lo - CELL_TOL && x <= lo + 1.0 + CELL_TOL
    };
    (inside(out.sigma1, cells.1) && inside(out.sigma2, cells.2) && inside(n_out, cells.0))
        .then_some((out, n_out))
}

/// The damped step (at most a quarter of the move), projected onto
/// `s2_min ≤ σ2 ≤ σ1` (`≤ N` when `N` is fixed); `None` when not finite.
#[inline(always)]
fn damped_step(
    s: Switches,
    (d1, d2): (f32, f32),
    n: f32,
    fixed_n: Option<f32>,
    s2_min: f32,
) -> Option<Switches> {
    let cap = 0.25 * hi(n, 4.0);
    let lim = |x: f32| lo(hi(x, -cap), cap);
    let mut s1 = s.sigma1 + lim(d1);
    let mut s2 = s.sigma2 + lim(d2);
    if let Some(n) = fixed_n {
        s1 = lo(s1, n);
    }
    s2 = hi(s2, s2_min);
    s1 = hi(s1, s2);
    if !(s1.is_finite() && s2.is_finite()) {
        return None;
    }
    Some(Switches {
        sigma1: s1,
        sigma2: s2,
    })
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
