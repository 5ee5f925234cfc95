//! The planner method chosen on the command line.

use galvo_planner::BisectionConfig;
use galvo_planner::jump::Method;

/// Planner choice on the command line.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum MethodArg {
    /// The patent's bisection on the move time with the minimum-energy input.
    Seed,
    /// Time-optimal bang-bang (rigid model only), solved in f32 as on the
    /// target.
    Optimal,
    /// The same, solved in f64 (reference).
    OptimalF64,
    /// Trapezoidal velocity profile (baseline).
    Tcurve,
    /// Jerk-limited S-curve profile (baseline).
    Scurve,
}

impl MethodArg {
    pub(crate) fn method(self, p: u32) -> Method {
        match self {
            MethodArg::Seed => Method::Bisection(BisectionConfig { p, bracket_s: None }),
            MethodArg::Optimal => Method::TimeOptimal,
            MethodArg::OptimalF64 => Method::TimeOptimalF64,
            MethodArg::Tcurve => Method::TCurve,
            MethodArg::Scurve => Method::SCurve,
        }
    }
    pub(crate) fn name(self) -> &'static str {
        match self {
            MethodArg::Seed => "seed",
            MethodArg::Optimal => "optimal",
            MethodArg::OptimalF64 => "optimal-f64",
            MethodArg::Tcurve => "tcurve",
            MethodArg::Scurve => "scurve",
        }
    }
}
