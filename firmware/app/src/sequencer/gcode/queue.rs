//! The G-code motion queue: blocks queued by [`crate::sequencer::gcode`] run one
//! after the other, each split into steps the actuators execute. Every
//! actuator is dispatched in one place ([`Session::send_step`](crate::sequencer::gcode::context::Session::send_step)):
//!
//! * gimbal: a servo move per path step (`path.step_cm`, arcs also within
//!   `$12`) at the programmed feed (servo speed permitting), laser lit
//!   while a lit G1/G2/G3 step moves, dark on G0 and jogs;
//! * galvo: a G0 or dark move is a jump ([`GalvoRequest::Point`] without
//!   dwell), a lit feed move is marked as a line stroke
//!   ([`GalvoRequest::Path`]) at F with the feed override, capped by
//!   `galvo.mark_speed_mm_s`; arcs as chords within `$12`. On the galvo
//!   alone, consecutive lit blocks are joined into one stroke
//!   ([`crate::sequencer::drivers::galvo`]).
//!
//! Feed hold stops after the step in flight, laser dark; `~` goes on
//! from there. The galvo stops at once, braking along its stroke, and
//! the hold waits (`Hold:1`) for it to report where marking stopped: `~`
//! goes on from that point ([`crate::sequencer::drivers::galvo`]).

use crate::domain::PointCm;
use crate::domain::units::cm_from_mm;
use crate::grbl::report::Overrides;
use crate::grbl::{Block, Blocks, PointMm};
use crate::sequencer::drivers::gimbal::Stream;
use embassy_time::Instant;
use heapless::Deque;

/// Blocks the motion queue holds (`$I` advertises it).
pub const PLANNER_BLOCKS: usize = 16;

/// Arrival deadband at the end of a G-code block on the gimbal: the
/// servo resolution, 0.1°.
pub(in crate::sequencer) const CORNER_DEADBAND_TENTHS: u16 = 1;
/// After arriving at the end of a block the gimbal settles this long, ms,
/// before the next block starts (the servos close in on their target
/// beyond the deadband), so corners are not cut.
pub(in crate::sequencer) const CORNER_SETTLE_MS: u64 = 40;

/// Most steps one block is split into.
pub(in crate::sequencer) const MAX_STEPS: u32 = 100_000;

/// Feed hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::sequencer) enum Hold {
    /// Running.
    None,
    /// Stopping after the step in flight, or until the galvo reports
    /// where it stopped marking (laser already dark).
    Stopping,
    /// Stopped; `~` resumes.
    Held,
}

/// The block being executed, at step `index` of `count`.
#[derive(Debug, Clone, Copy)]
pub(in crate::sequencer) struct Current {
    pub(in crate::sequencer) block: Block,
    pub(in crate::sequencer) index: u32,
    pub(in crate::sequencer) count: u32,
    /// Where the step in flight started, mm.
    pub(in crate::sequencer) from: PointMm,
    /// Servo move in flight.
    pub(in crate::sequencer) servo_seq: Option<u32>,
    /// Galvo job in flight.
    pub(in crate::sequencer) galvo_seq: Option<u32>,
    /// Stepper move handed over, not yet taken (or, for the last block
    /// before rest, not yet at rest).
    pub(in crate::sequencer) stepper_seq: Option<u32>,
    /// End of a dwell.
    pub(in crate::sequencer) until: Option<Instant>,
    /// A jog cancel ends the block after the step in flight.
    pub(in crate::sequencer) cancelled: bool,
}

/// The queue and the motion in progress.
#[derive(Debug, Clone)]
pub(in crate::sequencer) struct Motion {
    pub(in crate::sequencer) queue: Deque<Block, PLANNER_BLOCKS>,
    /// Blocks of the line whose `ok` waits for room.
    pub(in crate::sequencer) owed: Option<Blocks>,
    pub(in crate::sequencer) current: Option<Current>,
    pub(in crate::sequencer) hold: Hold,
    /// Where the spot is (end of the last finished step), board mm.
    pub(in crate::sequencer) position: PointMm,
    /// A run start was noted (lights allowed) and no stop since.
    pub(in crate::sequencer) started: bool,
    /// The gimbal arrived somewhere since the start (before that its
    /// laser stays dark: it may be travelling from afar).
    pub(in crate::sequencer) arrived: bool,
    /// The gimbal laser should be lit.
    pub(in crate::sequencer) gimbal_lit: bool,
}

impl Motion {
    pub(in crate::sequencer) fn new() -> Self {
        Self {
            queue: Deque::new(),
            owed: None,
            current: None,
            hold: Hold::None,
            position: PointMm::ZERO,
            started: false,
            arrived: false,
            gimbal_lit: false,
        }
    }

    /// Nothing queued or running.
    pub(in crate::sequencer) fn is_idle(&self) -> bool {
        self.current.is_none() && self.queue.is_empty() && self.owed.is_none()
    }

    /// A jog runs or is queued.
    pub(in crate::sequencer) fn jogging(&self) -> bool {
        let jog = |b: &Block| matches!(b, Block::Jog { .. });
        self.current.is_some_and(|c| jog(&c.block)) || self.queue.iter().any(jog)
    }

    /// Feed (mm/min) and laser power S of what runs, after overrides.
    /// `stream`: the gimbal's.
    pub(in crate::sequencer) fn feed_and_power(
        &self,
        ov: &Overrides,
        stream: &Stream,
    ) -> (f64, f64) {
        let Some(current) = self.current.filter(|_| self.hold == Hold::None) else {
            return (0.0, 0.0);
        };
        let scale = |v: f64, percent: u8| v * f64::from(percent) / 100.0;
        // The gimbal's speed on its planned profile, when it streams.
        let feed = |f: f64| match stream.is_following() {
            true => stream.speed_mm_s() * 60.0,
            false => ov.feed_mm_min(f),
        };
        match current.block {
            Block::Line {
                feed_mm_min, laser, ..
            }
            | Block::Arc {
                feed_mm_min, laser, ..
            } => (feed(feed_mm_min), scale(laser.power, ov.spindle)),
            Block::Jog { feed_mm_min, .. } => (feed_mm_min, 0.0),
            _ => (0.0, 0.0),
        }
    }

    /// Drops everything; returns whether a line's `ok` was owed.
    pub(in crate::sequencer) fn clear(&mut self) -> bool {
        self.queue.clear();
        self.current = None;
        self.hold = Hold::None;
        self.started = false;
        self.arrived = false;
        self.gimbal_lit = false;
        self.owed.take().is_some()
    }
}

/// End point of a motion block.
pub(in crate::sequencer) fn block_end(block: &Block) -> Option<PointMm> {
    match *block {
        Block::Rapid { to, .. } | Block::Line { to, .. } | Block::Jog { to, .. } => Some(to),
        Block::Arc { arc, .. } => Some(arc.to),
        _ => None,
    }
}

/// Point `k` of `n` along a motion block.
pub(in crate::sequencer) fn point_at(block: &Block, k: u32, n: u32) -> PointMm {
    block_point(block, f64::from(k) / f64::from(n.max(1)))
}

/// The point a fraction `t` (0..=1) along a motion block.
pub(in crate::sequencer) fn block_point(block: &Block, t: f64) -> PointMm {
    match *block {
        Block::Rapid { from, to } | Block::Line { from, to, .. } | Block::Jog { from, to, .. } => {
            if t >= 1.0 {
                return to;
            }
            PointMm {
                x_mm: from.x_mm + (to.x_mm - from.x_mm) * t,
                y_mm: from.y_mm + (to.y_mm - from.y_mm) * t,
            }
        }
        Block::Arc { arc, .. } => arc.point_at(t),
        _ => PointMm::ZERO,
    }
}

pub(in crate::sequencer) fn cm(p: PointMm) -> PointCm {
    PointCm::new(cm_from_mm(p.x_mm), cm_from_mm(p.y_mm))
}

/// Shorter blocks are not planned (nothing to move).
pub(in crate::sequencer) const MIN_LENGTH_MM: f64 = 1e-4;

/// Length of a motion block, mm (`None`: not a motion, or nothing to move).
pub(in crate::sequencer) fn planned_length(block: &Block) -> Option<f64> {
    let length = match *block {
        Block::Rapid { from, to } | Block::Line { from, to, .. } | Block::Jog { from, to, .. } => {
            from.distance_to(to)
        }
        Block::Arc { arc, .. } => arc.length_mm(),
        _ => return None,
    };
    (length.is_finite() && length > MIN_LENGTH_MM).then_some(length)
}
