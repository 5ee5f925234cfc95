#![no_std]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::indexing_slicing,
        clippy::panic
    )
)]
//! Model-based galvo trajectories: the patent's bisection planner made
//! exact, a time-optimal planner, T/S-curve baselines, GRBL-style look-ahead
//! path marking, and the per-sample state-update integrator.
//!
//! `no_std` + `libm`; nothing allocates. Planning math is `f64`; the
//! per-sample integrator and path sampler are `f32` (the Cortex-M4F FPU is
//! single precision). Invalid input returns [`Error`], never panics. All
//! quantities are SI with the unit in the name (`theta_rad`, `ts_s`, `u_v`,
//! …) except the board plane of the path planner, which is in mm.
//!
//! # API map
//!
//! | module | what | key items |
//! |---|---|---|
//! | [`model`] | rigid `(θ, ω, I)` and flexible `(θ, ω, I, φ, ω_φ)` models, exact ZOH discretisation | [`RigidParams::model`], [`FlexParams::model`], [`LinearModel::discretize`] → [`Discrete`] |
//! | [`plan`] | one plan type for every method (below the planners) | [`JumpPlan`], [`XyJump`], [`MethodKind`], [`PlanInfo`] |
//! | [`jump`] | method dispatcher, two-axis jumps (above the planners) | [`plan_jump`], [`plan_xy_jump`], [`Method`], [`JumpSync`] |
//! | [`min_energy`] | minimum-energy input over N samples ([`gramian`]: its linear algebra) | [`min_energy::plan_min_energy`] |
//! | [`bisection`] | the patent's bisection planner (user-facing name `seed`) | [`bisection::plan_bisection`], [`BisectionConfig`] |
//! | [`fast_optimal`] | time-optimal rest-to-rest (rigid) in `f32`: the default [`Method::TimeOptimal`], µs on the M4F | [`fast_optimal::plan_time_optimal_fast`] |
//! | [`optimal`] | time-optimal rest-to-rest (rigid) in `f64`: reference and fallback ([`bang_bang`]: its input law) | [`optimal::plan_time_optimal`] |
//! | [`profile`] | T-curve / S-curve baselines ([`motion_profile`]: the profiles and their inverse-dynamics voltage) | [`profile::plan_profile`], [`profile::Profile`], [`profile::ProfileLimits::from_drive`] |
//! | [`integrator`] | per-sample `f32` state update, move queue, two axes | [`Integrator`], [`XyIntegrator`] |
//! | [`path`] | look-ahead marking of lines and arcs in the board plane | [`PathPlanner`], [`MarkLimits`], [`MarkSample`], [`BlockEnd`] |
//! | [`blocks`] | the galvo loop's per-sample blocks, compiled here for speed | [`blocks::fill_jump`], [`blocks::fill_marks`] |
//! | [`linalg`] | small fixed-size matrices, matrix exponential | [`linalg::expm_and_integral`] |
//!
//! Modules, bottom to top (each uses only those below it):
//! `error`, `linalg`, `bang_bang` → `rigid_modes` → `model` → `gramian`,
//! `motion_profile` → `plan` → `min_energy`, `bisection`, `profile`,
//! `optimal` → `fast_optimal`, `integrator` → `jump`; `path` stands alone
//! (board plane, mm). `finite`, `clamp` and the back-substitution come from
//! `kinematics_core::numeric`.
//!
//! # The galvo loop
//!
//! Jumps (laser off) run in mirror-angle space through an [`XyIntegrator`];
//! marked paths run in the board plane through a [`PathPlanner`], whose
//! samples the caller converts to mirror angles with the galvo kinematics
//! (another crate; a small-angle stand-in below). Per sample or per DMA
//! block:
//!
//! ```
//! use galvo_planner::{
//!     BlockEnd, JumpSync, MarkLimits, Method, PathPlanner, RigidParams, XyIntegrator, plan_xy_jump,
//! };
//!
//! // Stand-in for the galvo kinematics: board mm → mechanical mirror angles.
//! fn mm_to_rad(p: [f64; 2]) -> [f64; 2] {
//!     [p[0] / 800.0, p[1] / 800.0]
//! }
//!
//! let disc = RigidParams::REFERENCE.model()?.discretize(10e-6)?;
//! let mut mirrors: XyIntegrator<3, 1024> = XyIntegrator::new(&disc, &disc, [0.0, 0.0])?;
//! let limits = MarkLimits {
//!     speed_mm_s: 1000.0,
//!     accel_mm_s2: 1.0e5,
//!     junction_deviation_mm: 0.01,
//!     ts_s: 10e-6,
//! };
//! let mut path: PathPlanner<32> = PathPlanner::new(limits, [0.0, 0.0])?;
//! // Two separate marks: a square and a circle.
//! path.move_to([10.0, 10.0])?;
//! for p in [[20.0, 10.0], [20.0, 20.0], [10.0, 20.0], [10.0, 10.0]] {
//!     path.line_to(p)?;
//! }
//! path.move_to([-5.0, 0.0])?;
//! path.arc_to([-5.0, 0.0], [-10.0, 0.0], true)?;
//!
//! let mut block_mm = [[0.0f32; 2]; 64];
//! let mut block_rad = [[0.0f32; 2]; 64];
//! let mut jumps = 0;
//! loop {
//!     // Laser on while marking: positions straight from the path planner.
//!     let (n, end) = path.fill(&mut block_mm);
//!     for p in &block_mm[..n] {
//!         let _dac_angles = mm_to_rad([f64::from(p[0]), f64::from(p[1])]);
//!     }
//!     match end {
//!         BlockEnd::Full => continue,
//!         BlockEnd::Idle => break,
//!         BlockEnd::Jump { from_mm, to_mm } => {
//!             // Laser off. Seat the mirrors where the mark left them, plan
//!             // both axes (the longer move governs the jump time) and run.
//!             mirrors.hold_at(mm_to_rad(from_mm))?;
//!             let capacity = mirrors.x.free_samples().min(mirrors.y.free_samples());
//!             let jump = plan_xy_jump(
//!                 &disc, &disc, mirrors.end_position_rad(), mm_to_rad(to_mm),
//!                 Method::TimeOptimal, JumpSync::Independent, capacity,
//!             )?;
//!             mirrors.queue_jump(&jump)?;
//!             while !mirrors.is_idle() {
//!                 mirrors.fill(&mut block_rad); // → DAC
//!             }
//!             jumps += 1;
//!         }
//!     }
//! }
//! assert_eq!(jumps, 2);
//! assert_eq!(path.position_mm(), [-5.0, 0.0]);
//! # Ok::<(), galvo_planner::Error>(())
//! ```

pub mod bang_bang;
pub mod bisection;
pub mod blocks;
pub mod error;
pub mod fast_optimal;
pub mod gramian;
pub mod integrator;
pub mod jump;
pub mod linalg;
pub mod min_energy;
pub mod model;
pub mod motion_profile;
pub mod optimal;
pub mod path;
pub mod plan;
pub mod profile;
pub(crate) mod rigid_modes;
#[cfg(test)]
mod test_support;

pub use bisection::BisectionConfig;
pub use error::Error;
pub use integrator::{Integrator, XyIntegrator};
pub use jump::{JumpSync, Method, plan_jump, plan_xy_jump, plan_xy_jump_f32};
pub use model::{Discrete, FlexParams, LinearModel, ModelKind, RigidParams};
pub use path::{ArcRotor, BlockEnd, MarkLimits, MarkSample, PathPlanner};
pub use plan::{JumpPlan, MethodKind, PlanInfo, XyJump};
