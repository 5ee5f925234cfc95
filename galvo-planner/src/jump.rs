//! The method dispatcher and two-axis jumps: picks the planner for a
//! [`Method`] and plans both mirror axes of a jump. The plan type itself
//! lives below the planners, in [`plan`](crate::plan).

use crate::bang_bang::FastMove;
use crate::bisection::{self, BisectionConfig};
use crate::error::Error;
use crate::fast_optimal::solve_f32;
use crate::min_energy;
use crate::model::Discrete;
use crate::plan::{JumpPlan, MethodKind, XyJump};
use crate::profile::{self, ProfileKind};
use kinematics_core::numeric::finite;

/// Which planner to use for a jump.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// The patent's method made exact: bisection on the move time with the
    /// minimum-energy input that lands on the target.
    Bisection(BisectionConfig),
    /// Shortest rest-to-rest move under `|U| ≤ Umax` on the sample grid
    /// (rigid model only), planned in single precision
    /// ([`fast_optimal`](crate::fast_optimal); `f64`
    /// [`optimal`](crate::optimal) where that does not apply).
    TimeOptimal,
    /// The same plan solved in `f64` ([`optimal`](crate::optimal)): the
    /// reference for comparisons on the host (milliseconds on the M4F).
    TimeOptimalF64,
    /// Trapezoidal velocity profile (baseline).
    TCurve,
    /// Jerk-limited S-curve profile (baseline).
    SCurve,
}

impl Method {
    /// The bisection method with the default `p = 8` (user-facing name `seed`).
    pub const BISECTION: Method = Method::Bisection(BisectionConfig::DEFAULT);

    /// Short lower-case name (`seed`, `optimal`, `tcurve`, `scurve`).
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }

    /// The method without its configuration.
    pub fn kind(&self) -> MethodKind {
        match self {
            Method::Bisection(_) => MethodKind::Bisection,
            Method::TimeOptimal | Method::TimeOptimalF64 => MethodKind::TimeOptimal,
            Method::TCurve => MethodKind::TCurve,
            Method::SCurve => MethodKind::SCurve,
        }
    }
}

/// Plans a rest-to-rest jump from `from_rad` to `to_rad` (motor angle; for
/// the flexible model the load ends at the same angle with zero speed) with
/// at most `capacity` samples.
pub fn plan_jump<const S: usize>(
    disc: &Discrete<S>,
    from_rad: f64,
    to_rad: f64,
    method: Method,
    capacity: usize,
) -> Result<JumpPlan<S>, Error> {
    let from_rad = finite(from_rad, "from_rad")?;
    let to_rad = finite(to_rad, "to_rad")?;
    let z0 = disc.model().rest_state(from_rad);
    let z1 = disc.model().rest_state(to_rad);
    match method {
        Method::Bisection(cfg) => bisection::plan_bisection(disc, &z0, &z1, cfg, capacity),
        Method::TimeOptimal => {
            crate::fast_optimal::plan_time_optimal_fast(disc, from_rad, to_rad, capacity)
        }
        Method::TimeOptimalF64 => {
            crate::optimal::plan_time_optimal(disc, from_rad, to_rad, capacity)
        }
        Method::TCurve => profile::plan_profile(
            disc,
            from_rad,
            to_rad,
            ProfileKind::Trapezoid,
            None,
            capacity,
        ),
        Method::SCurve => {
            profile::plan_profile(disc, from_rad, to_rad, ProfileKind::SCurve, None, capacity)
        }
    }
}

/// How the two axes of a jump are timed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum JumpSync {
    /// Each axis moves as fast as its planner allows; the jump is over when
    /// the slower axis lands (the faster one holds its target meanwhile).
    /// This is the shortest possible jump, and the default.
    #[default]
    Independent,
    /// The shorter move is re-planned with the minimum-energy input over the
    /// longer move's sample count, so both axes arrive together with less
    /// voltage on the short axis. Same jump time as `Independent`.
    SameDuration,
}

/// Plans a two-axis jump between mirror angles `from_rad = [θx, θy]` and
/// `to_rad`. The axes may have different galvos (`disc_x`, `disc_y`) but
/// must share the sample period.
pub fn plan_xy_jump<const S: usize>(
    disc_x: &Discrete<S>,
    disc_y: &Discrete<S>,
    from_rad: [f64; 2],
    to_rad: [f64; 2],
    method: Method,
    sync: JumpSync,
    capacity: usize,
) -> Result<XyJump<S>, Error> {
    if disc_x.ts_s() != disc_y.ts_s() {
        return Err(Error::InvalidSamplePeriod {
            ts_s: disc_y.ts_s(),
        });
    }
    let [fx, fy] = from_rad;
    let [tx, ty] = to_rad;
    let mut x = plan_jump(disc_x, fx, tx, method, capacity)?;
    let mut y = plan_jump(disc_y, fy, ty, method, capacity)?;
    if sync == JumpSync::SameDuration && x.samples() != y.samples() {
        let n = x.samples().max(y.samples());
        let short = if x.samples() < y.samples() {
            &mut x
        } else {
            &mut y
        };
        if short.samples() > 0 {
            let stretched = min_energy::plan_min_energy(
                short.discrete(),
                short.start_state(),
                short.target_state(),
                n,
            )?;
            if stretched.within_voltage_limit() {
                *short = stretched;
            }
        }
    }
    Ok(XyJump { x, y })
}

/// Both axes' time-optimal jumps planned in `f32` only
/// ([`plan_time_optimal_f32`](crate::fast_optimal::plan_time_optimal_f32):
/// no `f64` fallback, no other method), each axis as fast as it can
/// ([`JumpSync::Independent`]). For a CPU with a single-precision FPU only
/// (the M4F): it links none of the `f64` planners.
pub fn plan_xy_jump_f32<const S: usize>(
    disc_x: &Discrete<S>,
    disc_y: &Discrete<S>,
    from_rad: [f64; 2],
    to_rad: [f64; 2],
    capacity: usize,
) -> Result<XyJump<S>, Error> {
    let [x, y] = solve_xy_f32(disc_x, disc_y, from_rad, to_rad, capacity)?;
    Ok(XyJump {
        x: JumpPlan::fast(disc_x, x),
        y: JumpPlan::fast(disc_y, y),
    })
}

/// Both axes' `f32` moves, solved.
#[inline(always)]
fn solve_xy_f32<const S: usize>(
    disc_x: &Discrete<S>,
    disc_y: &Discrete<S>,
    from_rad: [f64; 2],
    to_rad: [f64; 2],
    capacity: usize,
) -> Result<[FastMove; 2], Error> {
    if disc_x.ts_s() != disc_y.ts_s() {
        return Err(Error::InvalidSamplePeriod {
            ts_s: disc_y.ts_s(),
        });
    }
    let solve = |disc, from: f64, to: f64| {
        solve_f32(
            disc,
            finite(from, "from_rad")?,
            finite(to, "to_rad")?,
            capacity,
        )
    };
    Ok([
        solve(disc_x, from_rad[0], to_rad[0])?,
        solve(disc_y, from_rad[1], to_rad[1])?,
    ])
}

#[cfg(test)]
mod tests;
