//! The PELCO port: PELCO-D / PELCO-P frames from a CCTV keyboard, DVR or
//! PTZ software (RS-485) as another way to command the active actuator.
//!
//! * [`task`]: the port's task body, generic over `embedded-io-async`
//!   `Read`/`Write`: decodes frames for this device ([`::pelco::Decoder`]),
//!   hands them to the session, sends what it asks through the console's
//!   command channel (quietly: see [`crate::outbound::Outbound::begin_quiet_command`])
//!   and writes the position replies;
//! * [`session`]: frames as the product's own commands (jogs, `goto`,
//!   `laser`, `stop`), presets, position replies;
//! * [`speed`]: the speed table; [`sight`]: angles of a board point.
//!
//! `pelco status` on the console reads [`PelcoStatus`].
//! See `docs/pelco.md`.

pub mod session;
pub mod sight;
pub mod speed;
pub mod task;

pub use self::session::{Request, Session, View};
pub use self::task::{PelcoLine, PelcoTask};
pub use crate::command::PelcoStatus;

#[cfg(test)]
mod tests;
