//! [`GalvoLink`], between the sequencer and the galvo loop: the requests,
//! the events, the latest parameters and the counters the loop publishes.

use core::sync::atomic::{AtomicBool, AtomicU8, AtomicU32, Ordering};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;

use super::dac::{RefillTime, Underrun};
use super::scan::types::{GalvoConfig, GalvoError, ScanPhase};
use crate::domain::Figure;

/// The worst refill time, published by the loop for `galvo status`
/// (zero cycles: nothing measured).
struct RefillStat {
    cycles: AtomicU32,
    cpu_hz: AtomicU32,
    window_cycles: AtomicU32,
}

impl RefillStat {
    const fn new() -> Self {
        Self {
            cycles: AtomicU32::new(0),
            cpu_hz: AtomicU32::new(0),
            window_cycles: AtomicU32::new(0),
        }
    }
}

/// What the sequencer asks of the galvo loop.
#[derive(Debug, Clone, Copy, PartialEq)]
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
    /// Mark a path: jump (laser off) to each stroke's start, settle,
    /// mark it with the laser on at the marking speed, laser-off delay.
    Path {
        /// Request number.
        seq: u32,
        /// What to draw (board cm; the loop takes its strokes in mm).
        path: Figure,
        /// Marking speed, mm/s (`None`: the configured
        /// `galvo.mark_speed_mm_s`, which also caps it).
        mark_speed_mm_s: Option<f32>,
    },
    /// Drop queued jobs, laser off at once; the mirrors finish the jump in
    /// flight (a jump is rest to rest) or brake along the stroke being
    /// marked, and hold. Also clears an underrun latch. (Closing the
    /// [`LaserGate`](crate::laser_gate::LaserGate) stops the loop the same
    /// way, without the latch, and cannot get lost in a full channel.)
    Stop,
}

/// What the galvo loop reports.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GalvoEvent {
    /// Point `seq` is done (jump, settle, dwell, laser-off delay) and the
    /// DAC has output its last sample.
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
    /// New parameters were refused (the old ones stay).
    ConfigRefused(GalvoError),
    /// A `Stop` (after a close of the gate) has taken effect and the
    /// mirrors are at rest: where marking ended when the gate closed, if
    /// a path was being marked then (`None`: nothing of one was lit).
    Stopped(Option<MarkStop>),
}

/// Where a stop caught a marked path: on line `line` (from 0) of path
/// `seq`'s stroke, at board point (`x_mm`, `y_mm`), the end of the last
/// half buffer the DAC output lit (within one half buffer of the close).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MarkStop {
    /// Request number of the path.
    pub seq: u32,
    /// Line of its stroke, from 0.
    pub line: u8,
    /// Board x, mm.
    pub x_mm: f32,
    /// Board y, mm.
    pub y_mm: f32,
}

/// Depth of the galvo request queue.
pub const GALVO_REQUEST_DEPTH: usize = 4;

/// Channels and counters between the sequencer and the galvo loop. Every
/// board has one; a galvo loop serves it only on a board with a galvo DAC
/// ([`Self::attached`]).
pub struct GalvoLink {
    /// Sequencer → galvo loop.
    pub requests: Channel<CriticalSectionRawMutex, GalvoRequest, GALVO_REQUEST_DEPTH>,
    /// New parameters (the latest wins), applied between points, never
    /// mid-move.
    pub config: Signal<CriticalSectionRawMutex, GalvoConfig>,
    /// Galvo loop → sequencer.
    pub events: Channel<CriticalSectionRawMutex, GalvoEvent, 4>,
    /// Underruns since boot.
    pub underruns: AtomicU32,
    /// Half buffers written since boot (liveness for the watchdog).
    pub halves: AtomicU32,
    /// Whether the laser mode lets the galvo light at all (`laser off`
    /// clears it); applied to every half buffer computed from then on.
    laser_allowed: AtomicBool,
    /// [`ScanPhase`] after the last half buffer.
    phase: AtomicU8,
    /// Points queued in the loop after the last half buffer.
    queued: AtomicU8,
    /// A galvo loop serves the link (set when it starts).
    attached: AtomicBool,
    /// The serving loop's board plans bisection jumps
    /// ([`DacStream::F64_PLANNING`](super::DacStream::F64_PLANNING)).
    pub(super) bisection: AtomicBool,
    /// The DAC's worst refill, when the board measures it.
    refill: RefillStat,
}

const PHASES: [ScanPhase; 7] = [
    ScanPhase::Idle,
    ScanPhase::Jumping,
    ScanPhase::Settling,
    ScanPhase::Dwelling,
    ScanPhase::Marking,
    ScanPhase::Braking,
    ScanPhase::LaserOffDelay,
];

impl GalvoLink {
    /// Whether a galvo loop serves the link (a board without a galvo DAC
    /// runs none: `target galvo|both` is refused).
    pub fn attached(&self) -> bool {
        self.attached.load(Ordering::Relaxed)
    }

    /// Marks the link served ([`GalvoLoop::run`](super::GalvoLoop::run) calls it when it starts).
    pub fn attach(&self) {
        self.attached.store(true, Ordering::Relaxed);
    }

    /// Whether the serving loop's board plans jumps by bisection
    /// (`planner seed`, see [`DacStream::F64_PLANNING`](super::DacStream::F64_PLANNING)).
    pub fn plans_bisection(&self) -> bool {
        self.bisection.load(Ordering::Relaxed)
    }

    /// Lets the galvo light its dwells and strokes (`true`, laser modes
    /// `auto` and `dwell`) or keeps every sample it computes from now on
    /// dark (`false`, `laser off`). The master gate still decides whether
    /// an allowed sample shines.
    pub fn allow_laser(&self, allowed: bool) {
        self.laser_allowed.store(allowed, Ordering::Relaxed);
    }

    /// Whether the laser mode lets the galvo light (see [`Self::allow_laser`]).
    pub fn laser_allowed(&self) -> bool {
        self.laser_allowed.load(Ordering::Relaxed)
    }

    /// The loop's phase and queued points after its last half buffer.
    pub fn state(&self) -> (ScanPhase, usize) {
        let phase = PHASES
            .get(usize::from(self.phase.load(Ordering::Relaxed)))
            .copied()
            .unwrap_or(ScanPhase::Idle);
        (phase, usize::from(self.queued.load(Ordering::Relaxed)))
    }

    /// Publishes the DAC's worst refill (the loop, after each half).
    pub fn publish_refill(&self, refill: Option<RefillTime>) {
        if let Some(t) = refill {
            self.refill.cpu_hz.store(t.cpu_hz, Ordering::Relaxed);
            self.refill
                .window_cycles
                .store(t.window_cycles, Ordering::Relaxed);
            self.refill.cycles.store(t.cycles, Ordering::Relaxed);
        }
    }

    /// The worst refill last published (`None`: not measured).
    pub fn refill(&self) -> Option<RefillTime> {
        let cycles = self.refill.cycles.load(Ordering::Relaxed);
        (cycles > 0).then(|| RefillTime {
            cycles,
            cpu_hz: self.refill.cpu_hz.load(Ordering::Relaxed),
            window_cycles: self.refill.window_cycles.load(Ordering::Relaxed),
        })
    }

    pub(super) fn publish(&self, phase: ScanPhase, queued: usize) {
        let code = PHASES.iter().position(|p| *p == phase).unwrap_or(0);
        self.phase.store(code as u8, Ordering::Relaxed);
        self.queued.store(queued.min(255) as u8, Ordering::Relaxed);
    }
}

impl GalvoLink {
    /// Empty channels, zero counters (usable in a `static`).
    pub const fn new() -> Self {
        Self {
            requests: Channel::new(),
            config: Signal::new(),
            events: Channel::new(),
            underruns: AtomicU32::new(0),
            halves: AtomicU32::new(0),
            laser_allowed: AtomicBool::new(true),
            phase: AtomicU8::new(0),
            queued: AtomicU8::new(0),
            attached: AtomicBool::new(false),
            bisection: AtomicBool::new(false),
            refill: RefillStat::new(),
        }
    }
}

impl Default for GalvoLink {
    fn default() -> Self {
        Self::new()
    }
}
