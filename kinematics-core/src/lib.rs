#![no_std]
#![forbid(unsafe_code)]
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
//! Geometry layer of the laser pointing controller (SPEC §4, §5).

pub mod error;
pub mod frames;
pub mod galvo;
pub mod gimbal;
pub mod grid;
pub mod path;
pub mod pattern;
pub mod real;
pub mod servo;
pub mod stepper;

pub use error::{Error, Joint};
pub use frames::{BoardFrame, BoardPoint, BoardPose, GlobalPoint, PointMm};
pub use galvo::{DacAxis, DacCode, DacCodes, Galvo, GalvoGeometry, MirrorAngles};
pub use gimbal::{Gimbal, GimbalGeometry, GimbalModel, JointAngles};
pub use grid::{Grid, GridIndex};
pub use path::{ArcSteps, Criterion, LineSteps, RectSteps, Rotation, Segment, UniformSampler};
pub use pattern::Pattern;
pub use real::Real;
pub use servo::{Direction, ServoAxis, WireAngles};
pub use stepper::StepperAxis;
