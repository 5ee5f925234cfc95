//! The domain vocabulary, below the settings and the task bodies: board
//! points and lengths ([`point`], [`units`] — the one place for cm ↔ mm),
//! patterns and path figures ([`figure`]: one description of what is
//! drawn, in board cm, as strokes of lines and arcs), what draws
//! ([`actuator`]), targets and the aiming chain ([`aim`]), the gimbal's
//! point-by-point interpolation of a path ([`path`]), and the checks that
//! refuse what cannot be drawn ([`check`], [`error`]).
//!
//! Nothing here knows about settings, channels or tasks: the settings
//! build an [`Aimer`] ([`Settings::aimer`](crate::settings::Settings::aimer)),
//! the sequencer holds it and passes it per point.

pub mod actuator;
pub mod aim;
pub mod check;
pub mod error;
pub mod figure;
pub mod path;
pub mod point;
pub mod units;

pub use actuator::{Actuator, AimModel};
pub use aim::{Aim, Aimer, Target};
pub use check::{MAX_PROBES, PatternCheck, check_pattern, check_target};
pub use error::PatternError;
pub use figure::{Figure, GridPattern, Pattern, Rotation, Segment, Segments, Stroke, StrokeCm};
pub use path::{PathCursor, pass_points};
pub use point::{BOARD_LIMIT_CM, PointCm};
pub use units::Unit;

#[cfg(test)]
mod tests;
