//! The bisection planner: the patent's method (CN105005322B) made exact
//! (user-facing name `seed`).
//!
//! It bisects the move time `T` in `[Tmin, Tmax]`: for each candidate it
//! computes the minimum-energy input ([`gramian`](crate::gramian)) over
//! `N = ⌈T/Ts⌉` samples and checks `max|u_k| ≤ Umax`; too large → `T`
//! becomes the new `Tmin`, else the new `Tmax`; after `p` halvings the
//! bracket is `(Tmax − Tmin)/2^p` wide and the plan uses `Tmax`.

use crate::error::{Error, positive};
use crate::gramian::{MinEnergySolution, min_energy_at, samples_for};
use crate::linalg::Vector;
use crate::model::Discrete;
pub use crate::plan::BisectionInfo;
use crate::plan::{InputLaw, JumpPlan, MethodKind, PlanInfo, effective_capacity, finite_state};
use kinematics_core::numeric::finite;

/// Largest number of halvings carried out (beyond ~60 the bracket is below
/// the resolution of `f64` anyway).
pub const MAX_HALVINGS: u32 = 64;

/// Configuration of the bisection planner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BisectionConfig {
    /// Number of halvings `p` (precision `(Tmax − Tmin)/2^p`).
    pub p: u32,
    /// Initial bracket `(Tmin, Tmax)` in seconds. `None`: `Tmax` is the first
    /// feasible time in `S·Ts, 2·S·Ts, 4·S·Ts, …` (at most the capacity) and
    /// `Tmin` the previous, infeasible one (0 if the first is feasible).
    pub bracket_s: Option<(f64, f64)>,
}

impl BisectionConfig {
    /// `p = 8`, automatic bracket.
    pub const DEFAULT: Self = Self {
        p: 8,
        bracket_s: None,
    };
}

impl Default for BisectionConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Feasibility margin in the bisection, so that the final refinement cannot
/// push a feasible sequence over the limit.
const LIMIT_MARGIN: f64 = 1e-9;

/// The bisection planner: bisection on the move time with the minimum-energy
/// input. See the module documentation.
pub fn plan_bisection<const S: usize>(
    disc: &Discrete<S>,
    z0: &Vector<S>,
    z1: &Vector<S>,
    cfg: BisectionConfig,
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
        Some((t_min_s, t_max_s)) => given_bracket(t_min_s, t_max_s, ts, capacity, &mut feasible)?,
        None => doubling_bracket(S, ts, capacity, &mut feasible)?,
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
    let (n, sol) = final_input(
        disc,
        (z0, z1),
        samples_for(hi, ts),
        capacity,
        &mut evaluations,
    )?;
    let info = BisectionInfo {
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
        MethodKind::Bisection,
        PlanInfo::Bisection(info),
    ))
}

/// Checks the caller's bracket `(t_min_s, t_max_s)`, s: ordered,
/// non-negative, within the capacity, and its upper end feasible.
fn given_bracket(
    t_min_s: f64,
    t_max_s: f64,
    ts: f64,
    capacity: usize,
    feasible: &mut impl FnMut(usize) -> bool,
) -> Result<(f64, f64), Error> {
    let t_min_s = finite(t_min_s, "t_min_s")?;
    let t_max_s = positive(t_max_s, "t_max_s")?;
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
    Ok((t_min_s, t_max_s))
}

/// The automatic bracket, s: `Tmax` the first feasible time in
/// `states·Ts, 2·states·Ts, 4·states·Ts, …` (at most the capacity), `Tmin`
/// the previous, infeasible one (0 if the first is feasible).
fn doubling_bracket(
    states: usize,
    ts: f64,
    capacity: usize,
    feasible: &mut impl FnMut(usize) -> bool,
) -> Result<(f64, f64), Error> {
    let mut lo = 0.0;
    let mut hi = states as f64 * ts;
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
    Ok((lo, hi))
}

/// Final input at `n` samples (from `Tmax`), with refinement. Rounding in
/// the refinement can only move the peak by ~1e-12 relative; the margin
/// covers it, but step on to the next sample count rather than ever exceed
/// Umax. Counts its evaluations into `evaluations`.
fn final_input<const S: usize>(
    disc: &Discrete<S>,
    (z0, z1): (&Vector<S>, &Vector<S>),
    mut n: usize,
    capacity: usize,
    evaluations: &mut u32,
) -> Result<(usize, MinEnergySolution<S>), Error> {
    let mut tries = 0;
    loop {
        *evaluations += 1;
        if n > capacity {
            return Err(Error::CapacityExceeded {
                needed: n,
                capacity,
            });
        }
        match min_energy_at(disc, z0, z1, n, 2) {
            Some(s) if s.max_abs_u_v <= disc.u_max_v() => return Ok((n, s)),
            _ if tries < 4 => {
                n += 1;
                tries += 1;
            }
            _ => return Err(Error::NoConvergence),
        }
    }
}

#[cfg(test)]
mod tests;
