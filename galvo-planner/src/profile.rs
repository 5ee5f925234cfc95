//! Baseline position profiles: trapezoidal (T-curve) and jerk-limited
//! S-curve, rest to rest, with limits derived from the model, and the
//! voltage each needs (inverse dynamics) to be followed by the galvo.
//!
//! ## Limits from the model
//!
//! For the rigid model (and the flexible one with `J = Jm + Jl`), following a
//! profile θ(t) needs `I = J·θ''/Kt` and
//! `U = Kt·θ' + (R·J/Kt)·θ'' + (L·J/Kt)·θ'''` (back-EMF + resistive +
//! inductive terms). The baselines share `Umax` among these terms so that
//! the continuous-time voltage cannot exceed it:
//!
//! * **T-curve**: `v_max = (Umax/2)/Kt` (half the back-EMF-limited no-load
//!   speed) and `a_max = Kt·(Umax/2)/(R·J)` (half the stall-current
//!   acceleration) — the textbook motor-curve limits. The inductance is
//!   ignored, so the step changes of acceleration need voltage spikes of
//!   `L·J·Δa/(Kt·Ts)` on the sample grid: this baseline exceeds `Umax`.
//! * **S-curve**: `v_max = (Umax/3)/Kt`, `a_max = Kt·(Umax/3)/(R·J)`,
//!   `j_max = Kt·(Umax/3)/(L·J)`: each term gets a third, so
//!   `|U| ≤ Umax` holds at every instant.
//!
//! ## Voltage on the sample grid
//!
//! The input held over sample k is the average of the continuous inverse
//! dynamics over `[k·Ts, (k+1)·Ts)`, which is exact in closed form:
//! `(Kt·Δθ + (R·J/Kt)·Δω + (L·J/Kt)·Δα)/Ts` with left limits of α (so an
//! acceleration step inside the sample contributes its impulse). The ZOH
//! model driven by these averages ends close to, but not exactly on, the
//! target; a minimum-norm correction `Γᵀ·λ` (the same machinery as the bisection
//! planner) makes it land exactly.

pub use crate::motion_profile::{Profile, ProfileKind, ProfileLimits};

use crate::error::Error;
use crate::gramian::{MinEnergySolution, gramian, solve};
use crate::linalg::{Vector, mat_vec, vec_sub};
use crate::model::{Discrete, Drive};
use crate::plan::{InputLaw, JumpPlan, MethodKind, PlanInfo, effective_capacity};
use kinematics_core::numeric::finite;

/// Plans a baseline jump: the profile, its sample-averaged inverse-dynamics
/// voltage and the minimum-norm landing correction. `limits: None` uses
/// [`ProfileLimits::from_drive`].
pub fn plan_profile<const S: usize>(
    disc: &Discrete<S>,
    from_rad: f64,
    to_rad: f64,
    kind: ProfileKind,
    limits: Option<ProfileLimits>,
    capacity: usize,
) -> Result<JumpPlan<S>, Error> {
    let from_rad = finite(from_rad, "from_rad")?;
    let to_rad = finite(to_rad, "to_rad")?;
    let z0 = disc.model().rest_state(from_rad);
    let z1 = disc.model().rest_state(to_rad);
    if from_rad == to_rad {
        return Ok(JumpPlan::hold(disc, z0));
    }
    let capacity = effective_capacity(capacity);
    let drive = *disc.model().drive();
    let limits = limits.unwrap_or_else(|| ProfileLimits::from_drive(kind, &drive, disc.u_max_v()));
    let profile = Profile::new(kind, to_rad - from_rad, limits)?;
    let ts = disc.ts_s();
    // Sample k covers [kTs, (k+1)Ts); the last one must contain the end
    // (and its acceleration step), hence floor + 1.
    let steps = libm::floor(profile.duration_s() / ts) + 1.0;
    if steps.is_nan() || steps >= capacity as f64 + 1.0 {
        return Err(Error::CapacityExceeded {
            needed: if steps >= usize::MAX as f64 {
                usize::MAX
            } else {
                steps as usize
            },
            capacity,
        });
    }
    let n_profile = (steps as usize).max(S);
    let (n, sol) = landing_correction(disc, &profile, &drive, (&z0, &z1), n_profile, capacity)?;
    let method = match kind {
        ProfileKind::Trapezoid => MethodKind::TCurve,
        ProfileKind::SCurve => MethodKind::SCurve,
    };
    Ok(JumpPlan::new(
        disc,
        z0,
        z1,
        n,
        InputLaw::Profile {
            profile,
            lambda: sol.lambda,
        },
        method,
        PlanInfo::Profile(profile),
    ))
}

/// The minimum-norm correction that makes the profile's averaged voltages
/// land exactly on `z1` from `z0`, over the profile's own `n_profile`
/// samples or, when the sampled model is nearly uncontrollable over so few
/// samples, up to `2·S` more.
fn landing_correction<const S: usize>(
    disc: &Discrete<S>,
    profile: &Profile,
    drive: &Drive,
    (z0, z1): (&Vector<S>, &Vector<S>),
    n_profile: usize,
    capacity: usize,
) -> Result<(usize, MinEnergySolution<S>), Error> {
    let ts = disc.ts_s();
    for n in n_profile..n_profile.saturating_add(2 * S + 1) {
        if n > capacity {
            return Err(Error::CapacityExceeded {
                needed: n,
                capacity,
            });
        }
        // Where the averaged voltages alone would land.
        let (an, _) = disc.power(n);
        let mut reached = mat_vec(&an, z0);
        let mut g = *disc.bd();
        for j in 0..n {
            let u = profile.average_u_v(drive, ts, n - 1 - j);
            for (r, gi) in reached.iter_mut().zip(g.iter()) {
                *r += gi * u;
            }
            g = mat_vec(disc.ad(), &g);
        }
        let d = vec_sub(z1, &reached);
        let w = gramian(disc, n);
        let offset = |k: usize| profile.average_u_v(drive, ts, k);
        if let Some(sol) = solve(disc, &w, &d, n, 2, &offset) {
            return Ok((n, sol));
        }
    }
    Err(Error::NotReachable { samples: n_profile })
}

#[cfg(test)]
mod tests;
