//! How the loop plans a two-axis jump on this board ([`Planning`]).

use galvo_planner::{Discrete, JumpSync, Method, XyJump, plan_xy_jump, plan_xy_jump_f32};

use super::types::{GalvoError, INTEGRATOR_CAPACITY};
use crate::galvo::dac::DacStream;

/// How the loop plans a two-axis jump from, to (rad) with a method.
type XyPlanner = fn(&Discrete<3>, [f64; 2], [f64; 2], Method) -> Result<XyJump<3>, GalvoError>;

/// The jump planning a board affords ([`DacStream::F64_PLANNING`]). Set
/// only where the board's type is known ([`Self::of`]), so a board
/// without `f64` planning links none of the `f64` planners.
#[derive(Clone, Copy)]
pub(super) struct Planning {
    /// Bisection and the `f64` fallback are allowed.
    f64: bool,
    pub(super) plan: XyPlanner,
}

impl Planning {
    /// A host: every method, `f64` where it needs it.
    pub(super) const HOST: Self = Self {
        f64: true,
        plan: plan_any,
    };
    /// A single-precision FPU (the M4F): time-optimal in `f32` only.
    pub(super) const F32: Self = Self {
        f64: false,
        plan: plan_f32,
    };

    /// The planning of the board that feeds `D`.
    pub(super) fn of<D: DacStream>() -> Self {
        if D::F64_PLANNING {
            Self::HOST
        } else {
            Self::F32
        }
    }

    /// `Err` when `method` does not fit this board:
    /// [`GalvoError::SeedTooSlow`] for bisection.
    pub(super) fn check(&self, method: Method) -> Result<(), GalvoError> {
        match method {
            _ if self.f64 => Ok(()),
            Method::TimeOptimal => Ok(()),
            Method::Bisection(_) => Err(GalvoError::SeedTooSlow),
            _ => Err(GalvoError::Planner),
        }
    }
}

/// Both axes, any method ([`Planning::HOST`]).
fn plan_any(
    disc: &Discrete<3>,
    from_rad: [f64; 2],
    to_rad: [f64; 2],
    method: Method,
) -> Result<XyJump<3>, GalvoError> {
    let sync = JumpSync::Independent;
    plan_xy_jump(
        disc,
        disc,
        from_rad,
        to_rad,
        method,
        sync,
        INTEGRATOR_CAPACITY,
    )
    .map_err(|_| GalvoError::Planner)
}

/// Both axes time-optimal in `f32`, no `f64` fallback ([`Planning::F32`]).
fn plan_f32(
    disc: &Discrete<3>,
    from_rad: [f64; 2],
    to_rad: [f64; 2],
    method: Method,
) -> Result<XyJump<3>, GalvoError> {
    Planning::F32.check(method)?;
    plan_xy_jump_f32(disc, disc, from_rad, to_rad, INTEGRATOR_CAPACITY)
        .map_err(|_| GalvoError::Planner)
}
