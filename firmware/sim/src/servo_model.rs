//! Simulated FashionStar serial-bus servos: pure models (no async, no I/O,
//! no clock of their own: time comes in as `now_us`) that parse the real
//! request bytes with the firmware's own decoder and answer with real
//! response frames.
//!
//! Behaviour modelled:
//! * set angle (code 8) moves linearly in time from the angle at command
//!   time to the target over `interval_ms`; set angle by interval (11) and
//!   by velocity (12) follow a trapezoidal velocity profile with the
//!   commanded acceleration/deceleration times ([`motion`]); a new command
//!   replaces the running one from wherever the servo is (the servo's
//!   default "interruptible" setting, SDK `FSUS_PARAM_RESPONSE_SWITCH`);
//! * sync (25) applies each contained entry to the addressed servo;
//! * damping (9) stops the servo where it is;
//! * targets are clamped to the servo's ±180.0° range; velocities below
//!   1 °/s are taken as 1 °/s (the SDK's minimum);
//! * the reported angle is the true angle rounded to 0.1°;
//! * ping, query angle, query monitor (fixed plausible voltage and
//!   temperature) and read data (addresses 1–5 and 34) are answered;
//!   motion commands are not (SDK default, no response);
//! * write data (code 4) to address 34 (`FSUS_PARAM_SERVO_ID`) with one
//!   byte 0–254 is answered `id, 34, 1` under the old id, and the servo
//!   answers to the new id from then on (255, the broadcast address, or
//!   another length is answered with result 0 and changes nothing); other
//!   addresses are not modelled and not answered;
//! * two servos with one id (they ship that way) both answer: see
//!   [`SimServoBus`] for the collision;
//! * fault injection: a slowness factor (every move takes `factor` times
//!   longer) and a silent flag (the servo still obeys commands but answers
//!   nothing, like a broken return line).

mod bus;
pub mod motion;
mod sim_servo;

pub use bus::{BusDirection, BusFrame, SimServoBus};
pub use sim_servo::{
    BAUD, BITS_PER_BYTE, BYTE_TIME_US, IDLE_CURRENT_MA, MOVING_CURRENT_MA, PROCESSING_DELAY_US,
    RANGE_TENTHS_DEG, SUPPLY_MV, SimServo, TEMPERATURE_RAW, quantise_tenths, wire_time_us,
};

#[cfg(test)]
mod setup_tests;
#[cfg(test)]
mod tests;
