//! The G-code motion queue: blocks queued by [`super::gcode`] run one
//! after the other, each split into steps the actuators execute. Every
//! actuator is dispatched in one place ([`Core::gcode_send_step`]):
//!
//! * gimbal: a servo move per path step (`path.step_cm`, arcs also within
//!   `$12`) at the programmed feed (servo speed permitting), laser lit
//!   while a lit G1/G2/G3 step moves, dark on G0 and jogs;
//! * galvo: a G0 or dark move is a jump ([`GalvoRequest::Point`] without
//!   dwell), a lit feed move is marked as a line stroke
//!   ([`GalvoRequest::Path`]), arcs as chords within `$12`.
//!
//! Feed hold stops after the step in flight (the galvo at once, braking
//! along its stroke), laser dark; `~` goes on from there.

use embassy_time::{Duration, Instant};
use heapless::Deque;

use super::laser::LaserEvent;
use super::machine::{Action, ActionSink, Core};
use crate::domain::{Figure, PointCm, Target};
use crate::galvo::GalvoRequest;
use crate::grbl::report::Overrides;
use crate::grbl::{Block, Blocks, PointMm, SpindleMode};
use crate::servo::task::ServoRequest;
use crate::settings::LaserMode;

/// Blocks the motion queue holds (`$I` advertises it).
pub const PLANNER_BLOCKS: usize = 16;

/// Arrival deadband at the end of a G-code block on the gimbal: the
/// servo resolution, 0.1°.
const CORNER_DEADBAND_TENTHS: u16 = 1;
/// After arriving at the end of a block the gimbal settles this long, ms,
/// before the next block starts (the servos close in on their target
/// beyond the deadband), so corners are not cut.
const CORNER_SETTLE_MS: u64 = 40;

/// Most steps one block is split into.
const MAX_STEPS: u32 = 100_000;

/// Feed hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Hold {
    /// Running.
    None,
    /// Stopping after the step in flight (laser already dark).
    Stopping,
    /// Stopped; `~` resumes.
    Held,
}

/// The block being executed, at step `index` of `count`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Current {
    pub(super) block: Block,
    index: u32,
    count: u32,
    /// Where the step in flight started, mm.
    from: PointMm,
    /// Servo move in flight.
    servo_seq: Option<u32>,
    /// Galvo job in flight.
    galvo_seq: Option<u32>,
    /// End of a dwell.
    until: Option<Instant>,
    /// A jog cancel ends the block after the step in flight.
    cancelled: bool,
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
    arrived: bool,
    /// The gimbal laser should be lit.
    pub(super) gimbal_lit: bool,
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
        match current.block {
            Block::Line {
                feed_mm_min, laser, ..
            }
            | Block::Arc {
                feed_mm_min, laser, ..
            } => (scale(feed_mm_min, ov.feed), scale(laser.power, ov.spindle)),
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
fn point_at(block: &Block, k: u32, n: u32) -> PointMm {
    let t = f64::from(k) / f64::from(n.max(1));
    match *block {
        Block::Rapid { from, to } | Block::Line { from, to, .. } | Block::Jog { from, to, .. } => {
            if k >= n {
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

fn cm(p: PointMm) -> PointCm {
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
        };
        match block {
            Block::Arc { .. } => (0..=16).all(|k| reachable(point_at(block, k, 16))),
            _ => reachable(end),
        }
    }

    /// Steps `block` is split into on the current actuator(s).
    fn step_count(&self, block: &Block) -> u32 {
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
                    let count = self.step_count(&block);
                    self.gcode.motion.current = Some(self.new_current(block, count));
                    self.gcode_send_step(out);
                }
            }
        }
    }

    fn new_current(&self, block: Block, count: u32) -> Current {
        Current {
            block,
            index: 1,
            count,
            from: self.gcode.motion.position,
            servo_seq: None,
            galvo_seq: None,
            until: None,
            cancelled: false,
        }
    }

    /// Whether laser setting (`mode`, `power`) lights a feed move.
    fn gcode_lit(&self, mode: SpindleMode, power: f64) -> bool {
        let v = &self.gcode.values;
        let fraction = crate::grbl::Laser { mode, power }.fraction(v.s_min, v.s_max);
        fraction > 0.0 && self.settings.laser_mode == LaserMode::Auto
    }

    /// Sends the current step to every actuator that draws.
    fn gcode_send_step(&mut self, out: &mut dyn ActionSink) {
        let motion = &self.gcode.motion;
        let Some(current) = motion.current else {
            return;
        };
        let to = point_at(&current.block, current.index, current.count);
        let (feed, lit) = match current.block {
            Block::Line {
                feed_mm_min, laser, ..
            }
            | Block::Arc {
                feed_mm_min, laser, ..
            } => (Some(feed_mm_min), self.gcode_lit(laser.mode, laser.power)),
            Block::Jog { feed_mm_min, .. } => (Some(feed_mm_min), false),
            _ => (None, false),
        };
        let lit = lit && motion.hold == Hold::None;
        let from = motion.position;
        let mut servo_seq = None;
        let mut galvo_seq = None;
        if self.actuator.uses_gimbal() {
            // The last step of a block ends at a corner: it must arrive
            // within the servo resolution, or the next block's first step
            // would cut the corner by up to the arrival deadband.
            let corner = current.index >= current.count;
            servo_seq = self.gcode_servo_move(from, to, feed, corner, out);
            if servo_seq.is_none() {
                return;
            }
            // Dark until the gimbal has arrived once since the start.
            self.gcode.motion.gimbal_lit = lit && self.gcode.motion.arrived;
        }
        if self.actuator.uses_galvo() {
            let galvo_lit = lit;
            self.next_seq = self.next_seq.wrapping_add(1);
            let seq = self.next_seq;
            let request = if galvo_lit {
                GalvoRequest::Path {
                    seq,
                    path: Figure::Line {
                        from: cm(from),
                        to: cm(to),
                    },
                }
            } else {
                let [x_mm, y_mm] = cm(to).galvo_mm();
                GalvoRequest::Point {
                    seq,
                    x_mm,
                    y_mm,
                    dwell_us: 0,
                }
            };
            if !self.send_galvo(request, out) {
                return;
            }
            galvo_seq = Some(seq);
        }
        if let Some(c) = self.gcode.motion.current.as_mut() {
            c.from = from;
            c.servo_seq = servo_seq;
            c.galvo_seq = galvo_seq;
        }
    }

    /// A servo move to `to` at `feed` mm/min (rapid: servo speed);
    /// returns its request number.
    fn gcode_servo_move(
        &mut self,
        from: PointMm,
        to: PointMm,
        feed: Option<f64>,
        corner: bool,
        out: &mut dyn ActionSink,
    ) -> Option<u32> {
        let point = cm(to);
        let Ok(aim) = self.aimer.aim(point) else {
            self.grbl_alarm(crate::grbl::Alarm::SoftLimit, out);
            return None;
        };
        let by_servo = self.move_interval_ms(&aim);
        let by_feed = feed.map_or(0.0, |f| {
            let f = f * f64::from(self.gcode.overrides.feed) / 100.0;
            60_000.0 * from.distance_to(to) / f.max(1e-3)
        });
        let interval_ms = libm::fmax(f64::from(by_servo), by_feed).min(f64::from(u16::MAX)) as u16;
        self.next_seq = self.next_seq.wrapping_add(1);
        let seq = self.next_seq;
        out.act(Action::Servo(ServoRequest::Move {
            seq,
            yaw_tenths: aim.yaw_wire,
            pitch_tenths: aim.pitch_wire,
            interval_ms,
            ids: (self.settings.yaw.id, self.settings.pitch.id),
            deadband_tenths: if corner {
                CORNER_DEADBAND_TENTHS
            } else {
                (self.settings.deadband_deg * 10.0) as u16
            },
            ranges_tenths: super::faults::servo_ranges_tenths(&self.settings),
        }));
        out.act(Action::Note(LaserEvent::GimbalMoveSent));
        self.last_aim = Some((Target { point, grid: None }, aim));
        Some(seq)
    }

    /// The servo task reports move `seq` arrived; `true` when it was the
    /// G-code step's.
    pub(super) fn gcode_servo_arrived(&mut self, seq: u32, out: &mut dyn ActionSink) -> bool {
        let Some(c) = self.gcode.motion.current.as_mut() else {
            return false;
        };
        if c.servo_seq != Some(seq) {
            return false;
        }
        c.servo_seq = None;
        if c.index >= c.count && c.count > 0 {
            c.until = Some(
                self.inputs
                    .now
                    .saturating_add(Duration::from_millis(CORNER_SETTLE_MS)),
            );
        }
        self.gcode.motion.arrived = true;
        out.act(Action::Note(LaserEvent::GimbalArrived));
        self.gcode_step_done(out);
        true
    }

    /// The galvo loop finished job `seq`; `true` when it was the G-code
    /// step's.
    pub(super) fn gcode_galvo_done(&mut self, seq: u32, out: &mut dyn ActionSink) -> bool {
        let Some(c) = self.gcode.motion.current.as_mut() else {
            return false;
        };
        if c.galvo_seq != Some(seq) {
            return false;
        }
        c.galvo_seq = None;
        self.gcode_step_done(out);
        true
    }

    /// When the dwell deadline passed: the dwell block is done.
    pub(super) fn gcode_dwell_check(&mut self, out: &mut dyn ActionSink) {
        let now = self.inputs.now;
        let Some(c) = self.gcode.motion.current.as_mut() else {
            return;
        };
        if c.until.is_some_and(|until| until <= now) {
            c.until = None;
            self.gcode.motion.gimbal_lit = false;
            self.gcode_step_done(out);
        }
    }

    /// When the G-code dwell ends.
    pub(super) fn gcode_deadline(&self) -> Option<Instant> {
        self.gcode.motion.current.and_then(|c| c.until)
    }

    /// Every actuator finished the step in flight: the next step, the next
    /// block, or the hold.
    fn gcode_step_done(&mut self, out: &mut dyn ActionSink) {
        let motion = &mut self.gcode.motion;
        let Some(mut c) = motion.current else { return };
        if c.servo_seq.is_some() || c.galvo_seq.is_some() || c.until.is_some() {
            return;
        }
        if c.count > 0 {
            motion.position = point_at(&c.block, c.index, c.count);
        }
        motion.gimbal_lit = false;
        c.index += 1;
        let finished = c.index > c.count || c.cancelled;
        motion.current = (!finished).then_some(c);
        if motion.hold == Hold::Stopping {
            motion.hold = Hold::Held;
            return;
        }
        if finished {
            if c.cancelled {
                self.grbl_sync_position();
            }
            self.grbl_advance(out);
        } else {
            self.gcode_send_step(out);
        }
    }

    /// `!`: laser dark at once; the gimbal stops after the step in
    /// flight, the galvo brakes along its stroke.
    pub(super) fn grbl_hold(&mut self, out: &mut dyn ActionSink) {
        let motion = &mut self.gcode.motion;
        if motion.hold != Hold::None || motion.is_idle() {
            return;
        }
        motion.gimbal_lit = false;
        let galvo_in_flight = motion.current.is_some_and(|c| c.galvo_seq.is_some());
        if let Some(c) = motion.current.as_mut() {
            // The galvo's step is redone from its start on resume.
            c.galvo_seq = None;
        }
        // A dwell runs to its end, dark; a servo move to its point.
        let waiting = motion
            .current
            .is_some_and(|c| c.servo_seq.is_some() || c.until.is_some());
        motion.hold = if waiting { Hold::Stopping } else { Hold::Held };
        if galvo_in_flight {
            self.stop_galvo(out);
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
        self.grbl_sync_position();
    }
}

impl Core {
    /// Whether the G-code step waits for servo move `seq`.
    pub(super) fn gcode_awaits_servo(&self, seq: u32) -> bool {
        self.gcode
            .motion
            .current
            .is_some_and(|c| c.servo_seq == Some(seq))
    }

    /// Whether the G-code step waits for galvo job `seq`.
    pub(super) fn gcode_awaits_galvo(&self, seq: u32) -> bool {
        self.gcode
            .motion
            .current
            .is_some_and(|c| c.galvo_seq == Some(seq))
    }
}
