//! Minimum-energy input from one state to another over a caller-chosen
//! number of samples (see [`gramian`](crate::gramian) for the math).

use crate::error::Error;
use crate::gramian::min_energy_at;
use crate::linalg::Vector;
use crate::model::Discrete;
use crate::plan::{InputLaw, JumpPlan, MAX_PLAN_SAMPLES, MethodKind, PlanInfo, finite_state};

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

#[cfg(test)]
mod tests;
