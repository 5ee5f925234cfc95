//! Error model and compensation (SPEC §5).
//!
//! Each axis' position error is a bivariate quadratic in the commanded
//! position, `Δ = c0 + c1·x + c2·y + c3·x² + c4·x·y + c5·y²` (x, y, Δ in mm,
//! board axes): the spot for a commanded point `c` lands at
//! `c + Δ(c)`. [`fit`] estimates the coefficients from measurements;
//! [`ErrorModel::compensate`] finds the command that lands on a target.

mod fit;
mod model;

pub use fit::{AxisFit, FitReport, MeasuredPoint, fit, sse_of};
pub use model::{
    COEF_LIMITS, COMPENSATION_TOL, ErrorModel, MAX_ITERATIONS, MAX_MEASURED_MM, N_COEF, Quadratic,
};
