//! The gimbal driver's stream: one point of the planned profile every period.

use crate::domain::Target;
use crate::grbl::block::MIN_FEED_MM_MIN;
use crate::grbl::{Block, PointMm};
use crate::sequencer::drivers::gimbal::{MIN_TICK_MS, STREAM_PERIOD_MS};
use crate::sequencer::gcode::queue::{
    CORNER_DEADBAND_TENTHS, Hold, block_point, cm, planned_length, point_at,
};
use crate::sequencer::machine::{ActionSink, Core};
use embassy_time::Duration;
use kinematics_core::lookahead::{LookaheadBlock, SpeedCursor};

impl Core {
    /// Whether G-code on this actuator streams through the planner (the
    /// gimbal alone).
    #[inline(never)]
    pub(in crate::sequencer) fn gcode_streams(&self) -> bool {
        self.drivers().gimbal_streams()
    }

    /// Starts following `block` (already popped from the motion queue):
    /// from rest, or on from the block before at the speed reached.
    /// `false` when it has nothing to move (it then runs step by step).
    #[inline(never)]
    pub(in crate::sequencer) fn stream_begin(
        &mut self,
        block: &Block,
        out: &mut dyn ActionSink,
    ) -> bool {
        let Some(length) = planned_length(block) else {
            return false;
        };
        self.stream_remember();
        let (cruise, accel) = self.stream_limits(block, length);
        let planned = LookaheadBlock {
            length,
            nominal_speed: cruise,
            accel,
            ..LookaheadBlock::default()
        };
        let stream = &mut self.jobs.gimbal;
        stream.cursor = Some(match stream.cursor {
            Some(mut c) => {
                c.continue_into(planned, 0.0);
                c
            }
            None => SpeedCursor::start(planned),
        });
        stream.cap_mm_s = cruise;
        if let Some(c) = self.gcode.motion.current.as_mut() {
            c.index = 0;
        }
        self.stream_tick(out);
        true
    }

    /// One period of the block being followed: the next point of the
    /// profile to the servos, the next tick scheduled — or the block's end
    /// reached (the next block, or the final move), or a hold at rest.
    #[inline(never)]
    pub(in crate::sequencer) fn stream_tick(&mut self, out: &mut dyn ActionSink) {
        let motion = &mut self.gcode.motion;
        let (Some(current), Some(mut cursor)) = (motion.current, self.jobs.gimbal.cursor) else {
            return;
        };
        let braking = motion.hold != Hold::None || current.cancelled;
        self.stream_remember();
        // The exit: the next block's entry while it joins at speed.
        cursor.block.exit_speed = self.stream_exit_speed(&current.block, &cursor);
        let joins = cursor.block.exit_speed > 0.0;
        // The feed override, never slower than grbl's minimum feed.
        let nominal_mm_s = cursor.block.nominal_speed.max(1e-9);
        let ov = f64::from(self.gcode.overrides.feed) / 100.0;
        let scale = ov
            .max(MIN_FEED_MM_MIN / 60.0 / nominal_mm_s)
            .min(self.jobs.gimbal.cap_mm_s / nominal_mm_s);
        let dt_ms = STREAM_PERIOD_MS as f64;
        let left = cursor.block.length - cursor.done;
        let over = cursor.advance(dt_ms / 1000.0, scale, braking);
        // A tick that reaches the block's end stops there, early.
        let tick_ms = over.map_or(dt_ms, |over| {
            (dt_ms * left / (left + over).max(1e-12)).max(MIN_TICK_MS)
        });
        self.jobs.gimbal.cursor = Some(cursor);
        let to = block_point(&current.block, cursor.fraction());
        let at_end = over.is_some();
        let final_move = at_end && !joins;
        if braking && cursor.is_at_rest() && !at_end {
            // A hold (or a jog cancel) came to rest on the path.
            self.stream_sample(to, tick_ms, false, out);
            return self.stream_rest(out);
        }
        if !self.stream_sample(to, tick_ms, final_move, out) {
            return;
        }
        let motion = &mut self.gcode.motion;
        let Some(c) = motion.current.as_mut() else {
            return;
        };
        c.index = u32::from(at_end);
        if final_move {
            // The last move of the burst waits for arrival and settles
            // (`gcode_servo_arrived`); what follows starts from rest.
            self.jobs.gimbal.cursor = None;
            return;
        }
        c.until = Some(
            self.inputs
                .now
                .saturating_add(Duration::from_micros((tick_ms * 1000.0) as u64)),
        );
    }

    /// The tick reached the end of a block that joins the next at speed:
    /// the next block (queued, planned) goes on from here, hold or not.
    #[inline(never)]
    pub(in crate::sequencer) fn stream_block_done(&mut self, out: &mut dyn ActionSink) {
        let motion = &mut self.gcode.motion;
        let mut cancelled = false;
        if let Some(c) = motion.current.take() {
            motion.position = point_at(&c.block, 1, 1);
            cancelled = c.cancelled;
        }
        let next = motion.queue.front().copied();
        match next.filter(|b| planned_length(b).is_some()) {
            Some(block) => {
                motion.queue.pop_front();
                self.grbl_take_owed(out);
                self.gcode.motion.current = Some(self.new_current(block, 1));
                if !self.stream_begin(&block, out) {
                    self.gcode.motion.current = None;
                    self.grbl_advance(out);
                }
            }
            None => {
                self.jobs.gimbal.cursor = None;
                if cancelled {
                    // A jog cancel between this block's end and the next:
                    // the parser had gone on to the dropped jogs' ends.
                    self.grbl_sync_position();
                }
                self.grbl_advance(out);
            }
        }
    }

    /// A servo move to `to` taking `tick_ms` (`last`: arrive within the
    /// servo resolution and report it); the laser lit as the block says.
    /// `false` when the point is out of reach (alarm raised).
    #[inline(never)]
    fn stream_sample(
        &mut self,
        to: PointMm,
        tick_ms: f64,
        last: bool,
        out: &mut dyn ActionSink,
    ) -> bool {
        let point = cm(to);
        let Ok(aim) = self.aimer.aim(point) else {
            self.grbl_alarm(crate::grbl::Alarm::SoftLimit, out);
            return false;
        };
        let deadband = if last {
            CORNER_DEADBAND_TENTHS
        } else {
            (self.settings.deadband_deg * 10.0) as u16
        };
        let interval_ms = (libm::ceil(tick_ms) as u16).max(1);
        let seq = self.send_gimbal_move(&aim, interval_ms, deadband, out);
        self.last_aim = Some((Target { point, grid: None }, aim));
        let lit = self.gcode_block_lit();
        self.gcode.step_speed_ratio = self.stream_speed_ratio();
        let motion = &mut self.gcode.motion;
        motion.position = to;
        motion.gimbal_lit = lit && motion.hold == Hold::None && motion.arrived;
        if let Some(c) = motion.current.as_mut() {
            c.servo_seq = Some(seq);
            c.until = None;
        }
        true
    }

    /// The speed now over the programmed feed (with the override), for M4.
    fn stream_speed_ratio(&self) -> f32 {
        let programmed = match self.gcode.motion.current.map(|c| c.block) {
            Some(Block::Line { feed_mm_min, .. } | Block::Arc { feed_mm_min, .. }) => {
                self.gcode.overrides.feed_mm_min(feed_mm_min) / 60.0
            }
            _ => return 0.0,
        };
        let ratio = self.jobs.gimbal.speed_mm_s() / programmed.max(1e-9);
        kinematics_core::numeric::clamp(ratio, 0.0, 1.0) as f32
    }

    /// Whether the running block lights the laser (a lit G1/G2/G3).
    #[inline(never)]
    fn gcode_block_lit(&self) -> bool {
        self.gcode
            .motion
            .current
            .is_some_and(|c| self.lights(&c.block))
    }

    /// Whether `block` lights the laser (a lit G1/G2/G3).
    #[inline(never)]
    pub(in crate::sequencer) fn lights(&self, block: &Block) -> bool {
        match *block {
            Block::Line { laser, .. } | Block::Arc { laser, .. } => {
                self.gcode_lit(laser.mode, laser.power)
            }
            _ => false,
        }
    }

    /// A hold came to rest (`~` goes on from here), or a jog cancel did
    /// (the jog ends here).
    #[inline(never)]
    fn stream_rest(&mut self, out: &mut dyn ActionSink) {
        let motion = &mut self.gcode.motion;
        motion.gimbal_lit = false;
        let cancelled = motion.current.is_some_and(|c| c.cancelled);
        if let Some(c) = motion.current.as_mut() {
            // The sample's arrival is not waited for.
            c.servo_seq = None;
            c.until = None;
        }
        if cancelled {
            motion.current = None;
            self.jobs.gimbal.clear();
            self.grbl_sync_position();
            self.grbl_advance(out);
            return;
        }
        motion.hold = Hold::Held;
    }

    /// The servo task confirmed streamed move `seq`: `true` when it was
    /// a point on the way (the block goes on at its own pace).
    #[inline(never)]
    pub(in crate::sequencer) fn stream_arrived(&mut self, seq: u32) -> bool {
        let motion = &mut self.gcode.motion;
        let on_the_way = self.jobs.gimbal.is_following()
            && motion.current.is_some_and(|c| c.servo_seq == Some(seq));
        if on_the_way {
            motion.arrived = true;
            if let Some(c) = motion.current.as_mut() {
                c.servo_seq = None;
            }
        }
        on_the_way
    }
}
