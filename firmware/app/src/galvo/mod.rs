//! The galvo task body: the periodic state-update loop that feeds the
//! hardware-timed two-channel DAC (SPEC §6).
//!
//! The DAC outputs one [`DacSample`] per sample period from a double
//! buffer; the loop wakes once per half buffer ([`DacStream::write_half`])
//! and fills the free half with the next samples: mirror angles from the
//! planner's per-sample stepper (`Z(k+1) = Ad·Z(k) + Bd·U(k)` per axis),
//! converted to 12-bit codes by the galvo DAC mapping, plus the laser bit.
//! Each requested point is a jump (laser off, planned by `galvo-planner`,
//! time-optimal or the patent's bisection method), a settling delay, a
//! dwell with the laser on, and a laser-off delay. A half the DAC had
//! already begun to replay is an underrun: counted, reported, laser off.
//!
//! Status: the loop body, its DAC interface and the simulated DAC are
//! done and tested; the sequencer commands (`target galvo`) and the
//! target's timer-triggered DAC DMA are not wired yet.

mod scan;

pub use scan::{GalvoConfig, GalvoError, GalvoLoop, Phase};

use core::sync::atomic::AtomicU32;

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;

/// One DAC sample: both 12-bit codes and the laser enable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DacSample {
    /// X mirror DAC code, 0..=4095.
    pub x_code: u16,
    /// Y mirror DAC code, 0..=4095.
    pub y_code: u16,
    /// Laser on during this sample.
    pub laser: bool,
}

/// The loop missed a refill deadline: the DAC replayed `halves` stale half
/// buffers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Underrun {
    /// Half buffers replayed.
    pub halves: u32,
}

/// A hardware-timed DAC fed from a double buffer: a timer-triggered DMA
/// on the target, a simulated DAC with the same deadlines on the host.
#[allow(async_fn_in_trait)]
pub trait DacStream {
    /// Samples per half buffer.
    fn half_len(&self) -> usize;

    /// Waits until the half the DAC is not reading is free, then stores
    /// `samples` (`half_len` of them) in it. `Err` when the DAC had
    /// already started on that half (the loop was late): the samples are
    /// then output one half late.
    async fn write_half(&mut self, samples: &[DacSample]) -> Result<(), Underrun>;
}

/// What the sequencer asks of the galvo loop.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GalvoRequest {
    /// Jump to a board point (mm, galvo frame) with the laser off, then
    /// dwell there with the laser on.
    Point {
        /// Request number.
        seq: u32,
        /// Board x, mm.
        x_mm: f32,
        /// Board y, mm.
        y_mm: f32,
        /// Laser-on time at the point, µs (0: just go there).
        dwell_us: u32,
    },
    /// Drop queued points, laser off at once; the mirrors finish the
    /// jump in flight (a jump is rest to rest) and hold.
    Stop,
}

/// What the galvo loop reports.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GalvoEvent {
    /// Point `seq` is done (jump, settle, dwell, laser-off delay).
    Done {
        /// Request number.
        seq: u32,
    },
    /// Point `seq` was refused (outside the DAC range, planning failed).
    Refused {
        /// Request number.
        seq: u32,
        /// Why.
        error: GalvoError,
    },
    /// The loop was late; the laser was turned off and queued points
    /// dropped.
    Underrun(Underrun),
}

/// Channels and counters between the sequencer and the galvo loop.
pub struct GalvoLink {
    /// Sequencer → galvo loop.
    pub requests: Channel<CriticalSectionRawMutex, GalvoRequest, 4>,
    /// Galvo loop → sequencer.
    pub events: Channel<CriticalSectionRawMutex, GalvoEvent, 4>,
    /// Underruns since boot.
    pub underruns: AtomicU32,
    /// Half buffers written since boot (liveness for the watchdog).
    pub halves: AtomicU32,
}

impl GalvoLink {
    /// Empty channels, zero counters (usable in a `static`).
    pub const fn new() -> Self {
        Self {
            requests: Channel::new(),
            events: Channel::new(),
            underruns: AtomicU32::new(0),
            halves: AtomicU32::new(0),
        }
    }
}

impl Default for GalvoLink {
    fn default() -> Self {
        Self::new()
    }
}
