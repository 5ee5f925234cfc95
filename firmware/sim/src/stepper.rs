//! The simulated stepper drivers and motors of a pan/tilt (SPEC §4.4, seed:
//! stepper light-spot): what a STEP/DIR driver (TB6600-like) and its motor
//! make of the firmware's pin edges.
//!
//! - **Counting**: each rising STEP edge moves the driver's position one
//!   microstep in the direction DIR holds (DIR high = negative).
//! - **Pulse timing**: STEP high and low at least [`DriverTiming::min_pulse_ns`],
//!   DIR stable at least [`DriverTiming::dir_setup_ns`] before a rising
//!   STEP edge and never changed while STEP is high. Violations are
//!   counted per kind (a real driver may miss or misdirect such a step).
//! - **Pull-out** ([`MotorLimits`]): the rotor is a mass pulled towards
//!   the commanded position by the motor's torque, which (as in a real
//!   hybrid stepper) varies as the sine of the load angle: full torque —
//!   the motor's acceleration limit `max_accel` — at one full step of lag,
//!   none at two, reversed beyond. The torque falls linearly with speed to
//!   none at `max_rate` (back-EMF; braking is not derated), and electrical damping (ζ = 0.4 at
//!   the small-signal resonance) acts on the rotor's speed relative to the
//!   commanded step rate. A step train the torque can follow keeps the
//!   lag under a full step; a commanded acceleration beyond `max_accel`,
//!   or a rate beyond `max_rate`, lets the lag pass two full steps (the
//!   unstable point; a slip is recorded at 2½, against wobble): the rotor
//!   slips poles, the motor **stalls**, steps are lost (the rotor
//!   settles whole electrical periods away) and the report says so. An
//!   abrupt halt from speed can stall too, when the rotor coasts past two
//!   full steps. The firmware never sees a stall (open loop, as on real
//!   hardware).
//!
//! The spot comes from the counted steps through the exact gimbal FK
//! ([`StepperGeometry::spot_cm`]).

mod axis;
mod drive;
mod pan_tilt;
mod switch;

pub use axis::{AxisDriver, DriverTiming, MotorLimits, Stall, TimingViolations};
pub use drive::{SimStepperDrive, TIMER_HZ};
pub use pan_tilt::{PanTiltDrivers, StepEdge, StepPin, StepperGeometry};
pub use switch::LimitSwitch;

#[cfg(test)]
mod tests;
