#![no_std]
// One `asm!` (the FPU square root, `real::sqrt_f32`) is allowed locally.
#![deny(unsafe_code)]
#![warn(missing_docs)]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::indexing_slicing,
        clippy::panic
    )
)]
//! Geometry layer of the laser pointing controller (SPEC §4, §5): frames,
//! servo-gimbal and two-mirror galvo kinematics, servo and stepper angle
//! mapping, grid patterns, path interpolation, and the quadratic error
//! model with its fit and compensation.
//!
//! `no_std` + `libm`; nothing allocates, nothing panics on any input:
//! invalid or non-finite input returns [`Error`], never NaN. Units are in
//! the names (`x_cm`, `yaw_deg`, `theta_rad`, `d_mm`). The gimbal geometry
//! and the error model are `f64`; the galvo kinematics and DAC mapping are
//! generic over [`Real`] so the firmware can run them in `f32` per sample.
//!
//! # API map
//!
//! | module | what | key items |
//! |---|---|---|
//! | [`frames`] | board ↔ global frames, board offsets and pose | [`BoardFrame`], [`BoardPose`], [`BoardPoint`], [`GlobalPoint`], [`PointMm`] |
//! | [`gimbal`] | exact (default) and seed gimbal FK/IK, the calibrated chain | [`Gimbal`] (`ik`, `fk`, `ik_wire`, `fk_wire`), [`GimbalModel`], [`JointAngles`], [`gimbal::exact`], [`gimbal::seed`] |
//! | [`servo`] | joint ↔ servo angle ↔ FashionStar wire value (0.1°) | [`ServoAxis`], [`Direction`], [`WireAngles`] |
//! | [`lookahead`] | grbl's junction-deviation look-ahead planner, unit-agnostic: the one planner of the gimbal, galvo and stepper | [`lookahead::Lookahead`], [`lookahead::SpeedCursor`] |
//! | [`ring`] | the fixed-capacity ring of the motion pipeline | [`ring::Ring`] |
//! | [`stepper`] | joint angle ↔ microsteps (0.05625°/step) | [`StepperAxis`] |
//! | [`galvo`] | two-mirror FK/IK with pincushion, DAC mapping (`f32`/`f64`), the per-sample `f32` map | [`Galvo`], [`GalvoGeometry`], [`DacAxis`], [`MirrorAngles`], [`DacCodes`], [`SampleMap`] |
//! | [`grid`] | grid geometry, index ↔ board point | [`Grid`], [`GridIndex`] |
//! | [`pattern`] | named test patterns as iterators | [`Pattern`] (`indices`, `points`) |
//! | [`path`] | comparison-method line/arc/rectangle, uniform sampler | [`LineSteps`], [`ArcSteps`], [`RectSteps`], [`UniformSampler`], [`Segment`] |
//! | [`error_model`] | quadratic error fit and compensation | [`fit`], [`ErrorModel`] (`predict`, `compensate`) |
//!
//! # Example
//!
//! ```
//! use kinematics_core::{BoardPoint, Gimbal, Grid, GridIndex, Pattern};
//!
//! let gimbal = Gimbal::default(); // exact model, SPEC geometry, ±135° servos
//! let grid = Grid::default(); // 1.916 cm pitch, 12 × 8 cells
//! for (idx, p) in Pattern::Corner.points(&grid)?.with_indices() {
//!     let wire = gimbal.ik_wire(p)?; // FashionStar angles, 0.1°
//!     assert!(idx.xi.abs() == 6 && wire.yaw != 0);
//! }
//! let j = gimbal.ik(grid.point(GridIndex::new(3, -2))?)?;
//! let back: BoardPoint = gimbal.fk(j)?;
//! assert!((back.x_cm - 3.0 * 1.916).abs() < 1e-9);
//! # Ok::<(), kinematics_core::Error>(())
//! ```

pub mod error;
pub mod error_model;
pub mod frames;
pub mod galvo;
pub mod gimbal;
pub mod grid;
pub mod lookahead;
pub mod numeric;
pub mod path;
pub mod pattern;
pub mod real;
pub mod ring;
pub mod servo;
pub mod stepper;

pub use error::{Error, Joint};
pub use error_model::{AxisFit, ErrorModel, FitReport, MeasuredPoint, Quadratic, fit};
pub use frames::{BoardFrame, BoardPoint, BoardPose, GlobalPoint, PointMm};
pub use galvo::{DacAxis, DacCode, DacCodes, Galvo, GalvoGeometry, MirrorAngles, SampleMap};
pub use gimbal::{Gimbal, GimbalGeometry, GimbalModel, JointAngles};
pub use grid::{Grid, GridIndex};
pub use path::{ArcSteps, Criterion, LineSteps, RectSteps, Rotation, Segment, UniformSampler};
pub use pattern::Pattern;
pub use real::{Real, sqrt_f32};
pub use servo::{Direction, ServoAxis, WireAngles};
pub use stepper::StepperAxis;
