//! The galvo task body: the periodic state-update loop that feeds the
//! hardware-timed two-channel DAC (SPEC §6).
//!
//! The DAC outputs one [`DacSample`] per sample period from a double
//! buffer; the loop wakes once per half buffer ([`DacStream::write_half`])
//! and fills the free half with the next samples: mirror angles from the
//! planner's per-sample integrator (`Z(k+1) = Ad·Z(k) + Bd·U(k)` per axis),
//! converted to 12-bit codes by the galvo DAC mapping, plus the laser bit.
//! Each requested point is a jump (laser off, planned by `galvo-planner`,
//! time-optimal or the patent's bisection method), a settling delay, a
//! dwell with the laser on, and a laser-off delay. A half the DAC had
//! already begun to replay is an underrun: counted, reported, laser off
//! (the master [`LaserGate`](crate::laser_gate::LaserGate) closes).
//! While nothing runs the loop holds: it lets the DAC replay the dark
//! hold both halves already hold instead of recomputing it, so an idle
//! loop cannot underrun.
//!
//! The sequencer drives it through [`GalvoLink`] (`target galvo|both`);
//! the simulator feeds a simulated DAC. Not wired yet: the target's
//! timer-triggered DAC DMA (see the README's status).

mod cost;
mod dac;
mod link;
mod scan;

pub use cost::{CostModel, LoopWork, M4_COST};
pub use dac::{DacSample, DacStream, Half, RefillTime, Underrun};
pub use link::{GALVO_REQUEST_DEPTH, GalvoEvent, GalvoLink, GalvoRequest, MarkStop};
pub use scan::memory::GalvoMemory;
pub use scan::{GalvoConfig, GalvoError, GalvoLoop, MAX_HALF_LEN, ScanPhase};
