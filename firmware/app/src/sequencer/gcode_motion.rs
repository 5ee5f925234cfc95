//! The G-code motion queue: blocks queued by [`super::gcode`] run one
//! after the other, each split into steps the actuators execute. Every
//! actuator is dispatched in one place ([`Core::gcode_send_step`]):
//!
//! * gimbal: a servo move per path step (`path.step_cm`, arcs also within
//!   `$12`) at the programmed feed (servo speed permitting), laser lit
//!   while a lit G1/G2/G3 step moves, dark on G0 and jogs;
//! * galvo: a G0 or dark move is a jump ([`GalvoRequest::Point`] without
//!   dwell), a lit feed move is marked as a line stroke
//!   ([`GalvoRequest::Path`]) at F with the feed override, capped by
//!   `galvo.mark_speed_mm_s`; arcs as chords within `$12`. On the galvo
//!   alone, consecutive lit blocks are joined into one stroke
//!   ([`super::gcode_galvo`]).
//!
//! Feed hold stops after the step in flight, laser dark; `~` goes on
//! from there. The galvo stops at once, braking along its stroke, and
//! the hold waits (`Hold:1`) for it to report where marking stopped: `~`
//! goes on from that point ([`super::gcode_galvo`]).

use embassy_time::{Duration, Instant};
use heapless::Deque;

use super::gcode_stepper::StepperJob;
use super::gcode_stream::{Stream, planned_length};
use super::laser::LaserEvent;
use super::machine::{Action, ActionSink, Core};
use crate::domain::PointCm;
use crate::grbl::report::Overrides;
use crate::grbl::{Block, Blocks, PointMm, SpindleMode};
use crate::settings::LaserMode;

/// Blocks the motion queue holds (`$I` advertises it).
pub const PLANNER_BLOCKS: usize = 16;

/// Arrival deadband at the end of a G-code block on the gimbal: the
/// servo resolution, 0.1°.
pub(super) const CORNER_DEADBAND_TENTHS: u16 = 1;
/// After arriving at the end of a block the gimbal settles this long, ms,
/// before the next block starts (the servos close in on their target
/// beyond the deadband), so corners are not cut.
pub(super) const CORNER_SETTLE_MS: u64 = 40;

/// Most steps one block is split into.
const MAX_STEPS: u32 = 100_000;

/// Feed hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Hold {
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
pub(super) struct Current {
    pub(super) block: Block,
    pub(super) index: u32,
    pub(super) count: u32,
    /// Where the step in flight started, mm.
    pub(super) from: PointMm,
    /// Servo move in flight.
    pub(super) servo_seq: Option<u32>,
    /// Galvo job in flight.
    pub(super) galvo_seq: Option<u32>,
    /// Stepper move handed over, not yet taken (or, for the last block
    /// before rest, not yet at rest).
    pub(super) stepper_seq: Option<u32>,
    /// End of a dwell.
    pub(super) until: Option<Instant>,
    /// A jog cancel ends the block after the step in flight.
    pub(super) cancelled: bool,
}

/// The queue and the motion in progress.
#[derive(Debug, Clone)]
pub(super) struct Motion {
    pub(super) queue: Deque<Block, PLANNER_BLOCKS>,
    /// Blocks of the line whose `ok` waits for room.
    pub(super) owed: Option<Blocks>,
    pub(super) current: Option<Current>,
    pub(super) hold: Hold,
    /// Where the spot is (end of the last finished step), board mm.
    pub(super) position: PointMm,
    /// A run start was noted (lights allowed) and no stop since.
    started: bool,
    /// The gimbal arrived somewhere since the start (before that its
    /// laser stays dark: it may be travelling from afar).
    pub(super) arrived: bool,
    /// The gimbal laser should be lit.
    pub(super) gimbal_lit: bool,
    /// The gimbal's look-ahead plan and the block it follows.
    pub(super) stream: Stream,
    /// What the stepper has of the job.
    pub(super) stepper: StepperJob,
}

impl Motion {
    pub(super) fn new() -> Self {
        Self {
            queue: Deque::new(),
            owed: None,
            current: None,
            hold: Hold::None,
            position: PointMm::ZERO,
            started: false,
            arrived: false,
            gimbal_lit: false,
            stream: Stream::new(),
            stepper: StepperJob::default(),
        }
    }

    /// Nothing queued or running.
    pub(super) fn is_idle(&self) -> bool {
        self.current.is_none() && self.queue.is_empty() && self.owed.is_none()
    }

    /// A jog runs or is queued.
    pub(super) fn jogging(&self) -> bool {
        let jog = |b: &Block| matches!(b, Block::Jog { .. });
        self.current.is_some_and(|c| jog(&c.block)) || self.queue.iter().any(jog)
    }

    /// Feed (mm/min) and laser power S of what runs, after overrides.
    pub(super) fn feed_and_power(&self, ov: &Overrides) -> (f64, f64) {
        let Some(current) = self.current.filter(|_| self.hold == Hold::None) else {
            return (0.0, 0.0);
        };
        let scale = |v: f64, percent: u8| v * f64::from(percent) / 100.0;
        // The gimbal's speed on its planned profile, when it streams.
        let feed = |f: f64| match self.stream.is_following() {
            true => self.stream.speed_mm_s() * 60.0,
            false => scale(f, ov.feed),
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
    fn clear(&mut self) -> bool {
        self.queue.clear();
        self.current = None;
        self.hold = Hold::None;
        self.started = false;
        self.arrived = false;
        self.gimbal_lit = false;
        self.stream.clear();
        self.stepper.clear();
        self.owed.take().is_some()
    }
}

/// End point of a motion block.
fn block_end(block: &Block) -> Option<PointMm> {
    match *block {
        Block::Rapid { to, .. } | Block::Line { to, .. } | Block::Jog { to, .. } => Some(to),
        Block::Arc { arc, .. } => Some(arc.to),
        _ => None,
    }
}

/// Point `k` of `n` along a motion block.
pub(super) fn point_at(block: &Block, k: u32, n: u32) -> PointMm {
    block_point(block, f64::from(k) / f64::from(n.max(1)))
}

/// The point a fraction `t` (0..=1) along a motion block.
pub(super) fn block_point(block: &Block, t: f64) -> PointMm {
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

pub(super) fn cm(p: PointMm) -> PointCm {
    PointCm::new(p.x_mm / 10.0, p.y_mm / 10.0)
}

impl Core {
    /// Whether every point of `block` is within grbl's soft limits: on
    /// the board (`$130` × `$131` about its centre) and within the reach
    /// of the actuator(s) (end points, and arcs along their sweep).
    pub(super) fn block_reachable(&self, block: &Block) -> bool {
        let Some(end) = block_end(block) else {
            return true;
        };
        let s = &self.settings;
        let half_width_mm = s.grid_pitch_cm * f64::from(s.grid_cols) * 5.0;
        let half_height_mm = s.grid_pitch_cm * f64::from(s.grid_rows) * 5.0;
        let reachable = |p: PointMm| {
            let on_board = libm::fabs(p.x_mm) <= half_width_mm + 1e-9
                && libm::fabs(p.y_mm) <= half_height_mm + 1e-9;
            let p = cm(p);
            on_board
                && (!self.actuator.uses_gimbal() || self.aimer.aim(p).is_ok())
                && (!self.actuator.uses_galvo() || self.aimer.galvo_in_range(p))
                && (!self.actuator.uses_stepper() || self.stepper_reaches(p))
        };
        match block {
            Block::Arc { .. } => (0..=16).all(|k| reachable(point_at(block, k, 16))),
            _ => reachable(end),
        }
    }

    /// Steps `block` is split into on the current actuator(s): one on the
    /// stepper, which takes a whole line or arc as one move and cuts it
    /// itself (a second step would hand it the same arc again, from its
    /// end: a full circle; issue 25).
    pub(super) fn step_count(&self, block: &Block) -> u32 {
        if self.actuator.uses_stepper() {
            return 1;
        }
        let step_mm = (self.aimer.path_step_cm() * 10.0).max(0.01);
        let gimbal = self.actuator.uses_gimbal();
        let steps =
            |length_mm: f64| libm::ceil(length_mm / step_mm).clamp(1.0, MAX_STEPS as f64) as u32;
        match *block {
            Block::Rapid { .. } => 1,
            Block::Line { from, to, .. } | Block::Jog { from, to, .. } if gimbal => {
                steps(from.distance_to(to))
            }
            Block::Arc { arc, .. } => {
                let chords = arc.segment_count(self.gcode.values.arc_tolerance_mm, MAX_STEPS);
                if gimbal {
                    chords.max(steps(arc.length_mm()))
                } else {
                    chords
                }
            }
            _ => 1,
        }
    }

    /// Starts the next block when nothing runs (and no hold), skipping
    /// blocks with nothing to move.
    pub(super) fn grbl_advance(&mut self, out: &mut dyn ActionSink) {
        while self.gcode.motion.current.is_none() && self.gcode.motion.hold == Hold::None {
            let Some(block) = self.gcode.motion.queue.pop_front() else {
                return;
            };
            self.grbl_take_owed(out);
            if !self.gcode.motion.started {
                // A G-code job starts like a run: what ran stops, nothing
                // of it may shine.
                if let Some(run) = self.run.take() {
                    crate::log::info!("stop {} (G-code started)", run.kind.name());
                    out.act(Action::Note(LaserEvent::Stopped {
                        why: "G-code started",
                    }));
                }
                out.act(Action::Note(LaserEvent::RunStarted));
                self.close_gate(out);
                self.gcode.motion.started = true;
            }
            match block {
                Block::Pause => self.gcode.motion.hold = Hold::Held,
                Block::End => {}
                Block::Dwell { seconds, laser } => {
                    let until = self
                        .inputs
                        .now
                        .saturating_add(Duration::from_micros((seconds.max(0.0) * 1e6) as u64));
                    self.gcode.motion.gimbal_lit = self.gcode_lit(laser.mode, laser.power)
                        && laser.mode == SpindleMode::Constant;
                    self.gcode.motion.current = Some(self.new_current(block, 0));
                    if let Some(c) = self.gcode.motion.current.as_mut() {
                        c.until = Some(until);
                    }
                }
                _ => {
                    if self.gcode_streams() && planned_length(&block).is_some() {
                        self.gcode.motion.current = Some(self.new_current(block, 1));
                        if self.stream_begin(&block, out) {
                            continue;
                        }
                    }
                    let count = self.step_count(&block);
                    self.gcode.motion.current = Some(self.new_current(block, count));
                    self.gcode_send_step(out);
                }
            }
        }
    }

    pub(super) fn new_current(&self, block: Block, count: u32) -> Current {
        Current {
            block,
            index: 1,
            count,
            from: self.gcode.motion.position,
            servo_seq: None,
            galvo_seq: None,
            stepper_seq: None,
            until: None,
            cancelled: false,
        }
    }

    /// Whether laser setting (`mode`, `power`) lights a feed move.
    pub(super) fn gcode_lit(&self, mode: SpindleMode, power: f64) -> bool {
        let v = &self.gcode.values;
        let fraction = crate::grbl::Laser { mode, power }.fraction(v.s_min, v.s_max);
        fraction > 0.0 && self.settings.laser_mode == LaserMode::Auto
    }

    /// `!`: laser dark at once; the gimbal stops after the step in
    /// flight, the galvo brakes along its stroke (held where it reports
    /// marking stopped).
    pub(super) fn grbl_hold(&mut self, out: &mut dyn ActionSink) {
        let motion = &self.gcode.motion;
        if motion.hold != Hold::None || motion.is_idle() || self.gcode_stepper_hold(out) {
            return;
        }
        let motion = &mut self.gcode.motion;
        motion.gimbal_lit = false;
        let galvo_in_flight = motion.current.is_some_and(|c| c.galvo_seq.is_some());
        // A galvo stroke: held where the galvo reports it stopped marking.
        let stroke = self.gcode_galvo_hold();
        let motion = &mut self.gcode.motion;
        if let Some(c) = motion.current.as_mut() {
            // Its `done` no longer counts: a galvo step (not a stroke) is
            // redone from its start on resume.
            c.galvo_seq = None;
        }
        // A dwell runs to its end, dark; a servo move to its point.
        let waiting = motion
            .current
            .is_some_and(|c| c.servo_seq.is_some() || c.until.is_some());
        motion.hold = if waiting || stroke {
            Hold::Stopping
        } else {
            Hold::Held
        };
        if galvo_in_flight {
            // Closing the gate also darkens the samples the DAC holds.
            self.close_gate(out);
        }
    }

    /// `~`: resumes after a hold (or an M0 pause).
    pub(super) fn grbl_resume(&mut self, out: &mut dyn ActionSink) {
        let motion = &mut self.gcode.motion;
        match motion.hold {
            Hold::None => {}
            Hold::Stopping => motion.hold = Hold::None,
            Hold::Held => {
                motion.hold = Hold::None;
                if motion.current.is_some() {
                    self.gcode_send_step(out);
                } else {
                    self.grbl_advance(out);
                }
            }
        }
    }

    /// 0x85: the jog stops after the step in flight; queued jogs dropped.
    pub(super) fn grbl_jog_cancel(&mut self, out: &mut dyn ActionSink) {
        if !self.gcode.motion.jogging() {
            return;
        }
        let motion = &mut self.gcode.motion;
        motion.queue.clear();
        let Some(c) = motion.current.as_mut() else {
            return;
        };
        c.cancelled = true;
        if c.galvo_seq.take().is_some() {
            self.stop_galvo(out);
            self.gcode_step_done(out);
        }
    }

    /// A stop from anywhere (`stop`, the button, a fault, a reset, an
    /// alarm): the queue is dropped; a line waiting for room is answered.
    pub(super) fn gcode_abort(&mut self, out: &mut dyn ActionSink) {
        if self.gcode.motion.clear() {
            self.ok(out);
        }
        self.gcode_galvo_hold_dropped();
        self.grbl_sync_position();
    }
}
