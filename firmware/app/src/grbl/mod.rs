//! grbl 1.1 protocol layer: what G-code senders (cncjs, Universal G-code
//! Sender, LaserGRBL, bCNC, gSender, Python streamers) speak. Pure code,
//! tested on the host; the console task and the motion queue use it.
//!
//! * [`realtime`]: realtime bytes (`?`, `!`, `~`, 0x18, 0x85, overrides)
//!   taken out of the byte stream before line assembly.
//! * [`classify`]: which language a line is in (G-code, `$` system
//!   command, or the product's own commands).
//! * [`words`] → [`collect`] → [`parser`]: a G-code line through grbl's
//!   word rules and modal state ([`state`]) into [`block`]s in board mm.
//! * [`system`]: `$` commands; [`settings_map`]: grbl's `$N` numbers.
//! * [`report`]: every reply grbl sends (`ok`, `error:N`, `ALARM:N`,
//!   status reports, `$G`, `$#`, `$I`, `$$`).
//! * [`error`]: grbl's error and alarm numbers.

pub mod block;
pub mod classify;
pub mod collect;
pub mod error;
pub mod parser;
pub mod realtime;
pub mod report;
pub mod settings_map;
pub mod state;
pub mod system;
pub mod words;

pub use block::{Arc, Block, Blocks, Laser, PointMm, SpindleMode};

/// grbl's RX buffer, bytes: the console's input buffer between the host
/// and line assembly (`$I` advertises it; a character-counting sender
/// keeps at most this many bytes unanswered).
pub const RX_BUFFER_BYTES: usize = 128;
pub use error::{Alarm, GrblError};
pub use state::ParserState;

#[cfg(test)]
mod tests;
