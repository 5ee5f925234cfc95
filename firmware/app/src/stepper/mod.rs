//! The stepper pan/tilt (SPEC §4.4; seeds: stepper light-spot, grbl
//! pan-tilt): two STEP/DIR axes — pan (yaw) and tilt (pitch) — and a
//! shared ENABLE, driven in grbl's shape.
//!
//! ```text
//! sequencer ─StepperRequest─▶ stepper task (low priority, f64):
//!     board point → IK per piece end → planner → segment prep ─┐
//!                                                               ▼ segment queue
//! step timer (high priority, integers only): StepGenerator::tick ─▶ STEP/DIR pins
//! ```
//!
//! The high-priority part ([`StepPulseTask`], one [`StepperLink::step_tick`]
//! per step event) does no planning, no `f64` and no division: a lock, a
//! ring pop and Bresenham adds. Everything else ([`StepperMotion`]) runs in
//! the low-priority [`StepperTask`].

mod config;
mod drive;
mod home;
mod link;
mod motion;
mod one_pulse;
mod pace;
mod task;

pub use self::config::{DriverSignals, HomingConfig, SEGMENT_S, STEP_TIMER_HZ, StepperConfig};
pub use self::drive::StepperDrive;
pub use self::link::{
    HomingFailure, MoveShape, STEP_QUEUE_LEN, StepperEvent, StepperLink, StepperRefusal,
    StepperRequest,
};
pub use self::motion::{LINE_TOLERANCE_MM, StepperMotion};
pub use self::one_pulse::{CCMR1_IDLE, OnePulse, OnePulseTiming};
pub use self::pace::StepPace;
pub use self::task::{StepPulseTask, StepperTask};

#[cfg(test)]
mod tests;
