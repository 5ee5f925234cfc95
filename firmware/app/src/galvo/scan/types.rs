//! The galvo loop's own types (no behaviour of the loop): its limits,
//! configuration, errors, phases and jobs.

use core::fmt;

use galvo_planner::{Method, RigidParams};
use kinematics_core::{Galvo, PointMm};

use crate::domain::Figure;

/// Jump input samples the integrator holds per axis (10.24 ms at 100 kHz,
/// longer than any full-range time-optimal jump of the reference galvo).
pub const INTEGRATOR_CAPACITY: usize = galvo_planner::blocks::JUMP_CAPACITY;
/// Longest half buffer the loop fills, samples.
pub const MAX_HALF_LEN: usize = 512;
/// Steps the prep stage prepares per half buffer in [`GalvoLoop::run`]:
/// one stroke step and the refill fit the 1.28 ms window (bench-m4's
/// `loop.*.prep` and `loop.*.refill`); more could overrun it.
pub(super) const PREP_PER_HALF: usize = 1;
/// Jobs queued inside the loop (beyond the request channel).
pub(super) const JOB_QUEUE: usize = 4;
/// Look-ahead blocks of the path planner (a stroke has at most 4).
pub(super) const MARK_BLOCKS: usize = galvo_planner::blocks::MARK_BLOCKS;

/// Galvo loop parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GalvoConfig {
    /// DAC sample period, s (10 µs = 100 kHz).
    pub sample_period_s: f64,
    /// Mirror geometry and DAC mapping.
    pub galvo: Galvo<f32>,
    /// Mirror drive model (both axes), for jump planning.
    pub mirrors: RigidParams,
    /// Jump planner: time-optimal (default) or the patent's bisection.
    pub method: Method,
    /// Hold after a jump lands, laser still off (mirror settling), µs.
    pub laser_on_delay_us: u32,
    /// Hold after the laser turns off, before the next jump, µs.
    pub laser_off_delay_us: u32,
    /// Marking speed, mm/s.
    pub mark_speed_mm_s: f64,
    /// Marking acceleration (and braking on stop), mm/s².
    pub mark_accel_mm_s2: f64,
    /// Junction deviation of the marking path planner (grbl's `$11`,
    /// the `gcode.junction_mm` setting), mm: larger corners faster.
    pub junction_deviation_mm: f64,
}

/// Why the loop cannot be built or a job cannot run.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GalvoError {
    /// Galvo kinematics refused the point (non-finite, invalid geometry).
    Kinematics,
    /// The point or path is outside the DAC's range.
    OutOfRange,
    /// The jump or path planner refused (invalid model or limits, jump
    /// too long for the integrator's buffer, path too short).
    Planner,
    /// More jobs than the loop queues.
    QueueFull,
    /// An underrun latched the laser off; a `Stop` clears it.
    Faulted,
    /// The board cannot plan jumps by bisection (`planner seed`) in time
    /// ([`DacStream::F64_PLANNING`](crate::galvo::dac::DacStream::F64_PLANNING)).
    SeedTooSlow,
}

impl fmt::Display for GalvoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            GalvoError::Kinematics => "galvo kinematics refused the point",
            GalvoError::OutOfRange => "outside the galvo's DAC range",
            GalvoError::Planner => "galvo planner refused the move",
            GalvoError::QueueFull => "galvo job queue is full",
            GalvoError::Faulted => "galvo underrun: send stop before new points",
            GalvoError::SeedTooSlow => {
"planner seed does not fit this board (bisection: 12-58 ms per jump axis); use planner optimal"
            }
        })
    }
}

/// What the galvo loop's mirrors and laser are doing (the sequencer's
/// point phase is [`crate::status::Phase`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ScanPhase {
    /// Holding, laser off, nothing queued.
    Idle,
    /// Jumping to a point or stroke start, laser off.
    Jumping,
    /// Landed; laser-on delay.
    Settling,
    /// Laser on at a point.
    Dwelling,
    /// Laser on, marking a stroke of a path.
    Marking,
    /// Stopped while marking: decelerating along the path, laser off.
    Braking,
    /// Laser off; laser-off delay before the next jump.
    LaserOffDelay,
}

/// A queued job.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Job {
    /// Jump to a point and dwell there (µs).
    Point { target_mm: PointMm, dwell_us: u32 },
    /// Mark a path, stroke by stroke (in mm, see
    /// [`Unit::GalvoMm`](crate::domain::Unit::GalvoMm)), at a marking
    /// speed (mm/s; `None`: the configured one).
    Path(Figure, Option<f32>),
}

/// The job being run.
#[derive(Debug, Clone, Copy)]
pub(super) struct Active {
    pub(super) seq: u32,
    pub(super) job: Job,
    /// Stroke of a path being drawn.
    pub(super) stroke: usize,
    pub(super) phase: ScanPhase,
    /// Samples left in a timed phase.
    pub(super) samples_left: u32,
    /// `stop` arrived: finish the jump (or brake) and hold, dark.
    pub(super) cancelled: bool,
}

impl Active {
    /// Enters `phase` for `samples` samples.
    pub(super) fn enter(&mut self, phase: ScanPhase, samples: u32) {
        self.phase = phase;
        self.samples_left = samples;
    }
}
