//! The gimbal driver's stream: one point of the planned profile every period.

use crate::domain::Target;
use crate::grbl::block::MIN_FEED_MM_MIN;
use crate::grbl::{Alarm, Block, PointMm};
use crate::sequencer::drivers::gimbal::plan::{stream_exit_speed, stream_limits};
use crate::sequencer::drivers::gimbal::step::servo_move;
use crate::sequencer::drivers::gimbal::{MIN_TICK_MS, STREAM_PERIOD_MS, Stream};
use crate::sequencer::drivers::stage::Stage;
use crate::sequencer::gcode::queue::{Hold, block_point, cm, planned_length};
use crate::sequencer::io::ActionSink;
use embassy_time::Duration;
use kinematics_core::lookahead::{LookaheadBlock, SpeedCursor};

impl Stream {
    /// Starts following `block` (already popped from the motion queue,
    /// the block in flight): from rest, or on from the block before at
    /// the speed reached. `None` when it has nothing to move (it then
    /// runs step by step); else what its first tick returns
    /// ([`Self::tick`]).
    #[inline(never)]
    pub(in crate::sequencer) fn begin(
        &mut self,
        st: &mut Stage,
        block: &Block,
        out: &mut dyn ActionSink,
    ) -> Option<bool> {
        let length = planned_length(block)?;
        self.remember(st);
        let (cruise, accel) = stream_limits(st, &self.deg_per_mm, block, length);
        let planned = LookaheadBlock {
            length,
            nominal_speed: cruise,
            accel,
            ..LookaheadBlock::default()
        };
        self.cursor = Some(match self.cursor {
            Some(mut c) => {
                c.continue_into(planned, 0.0);
                c
            }
            None => SpeedCursor::start(planned),
        });
        self.cap_mm_s = cruise;
        if let Some(c) = st.gcode.motion.current.as_mut() {
            c.index = 0;
        }
        Some(self.tick(st, out))
    }

    /// One period of the block being followed: the next point of the
    /// profile to the servos, the next tick scheduled — or the block's end
    /// reached (the next block, or the final move). `true` when a hold
    /// (or a jog cancel) came to rest on the path: the session then holds
    /// (or ends the jog) there.
    #[inline(never)]
    pub(in crate::sequencer) fn tick(&mut self, st: &mut Stage, out: &mut dyn ActionSink) -> bool {
        self.remember(st);
        let motion = &mut st.gcode.motion;
        let (Some(current), Some(mut cursor)) = (motion.current, self.cursor) else {
            return false;
        };
        let braking = motion.hold != Hold::None || current.cancelled;
        // The exit: the next block's entry while it joins at speed.
        cursor.block.exit_speed = stream_exit_speed(st, &self.deg_per_mm, &current.block, &cursor);
        let joins = cursor.block.exit_speed > 0.0;
        // The feed override, never slower than grbl's minimum feed.
        let nominal_mm_s = cursor.block.nominal_speed.max(1e-9);
        let ov = f64::from(st.gcode.overrides.feed) / 100.0;
        let scale = ov
            .max(MIN_FEED_MM_MIN / 60.0 / nominal_mm_s)
            .min(self.cap_mm_s / nominal_mm_s);
        let dt_ms = STREAM_PERIOD_MS as f64;
        let left = cursor.block.length - cursor.done;
        let over = cursor.advance(dt_ms / 1000.0, scale, braking);
        // A tick that reaches the block's end stops there, early.
        let tick_ms = over.map_or(dt_ms, |over| {
            (dt_ms * left / (left + over).max(1e-12)).max(MIN_TICK_MS)
        });
        self.cursor = Some(cursor);
        let to = block_point(&current.block, cursor.fraction());
        let at_end = over.is_some();
        let final_move = at_end && !joins;
        if braking && cursor.is_at_rest() && !at_end {
            // A hold (or a jog cancel) came to rest on the path.
            self.sample(st, to, tick_ms, false, out);
            return true;
        }
        if !self.sample(st, to, tick_ms, final_move, out) {
            return false;
        }
        let motion = &mut st.gcode.motion;
        let Some(c) = motion.current.as_mut() else {
            return false;
        };
        c.index = u32::from(at_end);
        if final_move {
            // The last move of the burst waits for arrival and settles
            // (`servo_arrived`); what follows starts from rest.
            self.cursor = None;
            return false;
        }
        c.until = Some(
            st.inputs
                .now
                .saturating_add(Duration::from_micros((tick_ms * 1000.0) as u64)),
        );
        false
    }

    /// A servo move to `to` taking `tick_ms` (`last`: arrive within the
    /// servo resolution and report it); the laser lit as the block says.
    /// `false` when the point is out of reach (alarm raised).
    #[inline(never)]
    fn sample(
        &mut self,
        st: &mut Stage,
        to: PointMm,
        tick_ms: f64,
        last: bool,
        out: &mut dyn ActionSink,
    ) -> bool {
        let point = cm(to);
        let Ok(aim) = st.aimer.aim(point) else {
            st.alarm = Some(Alarm::SoftLimit);
            return false;
        };
        let interval_ms = (libm::ceil(tick_ms) as u16).max(1);
        let target = Target { point, grid: None };
        let seq = servo_move(st, target, aim, interval_ms, last, out);
        let lit = block_lit(st);
        st.gcode.step_speed_ratio = self.speed_ratio(st);
        let motion = &mut st.gcode.motion;
        motion.position = to;
        motion.gimbal_lit = lit && motion.hold == Hold::None && motion.arrived;
        if let Some(c) = motion.current.as_mut() {
            c.servo_seq = Some(seq);
            c.until = None;
        }
        true
    }

    /// The speed now over the programmed feed (with the override), for M4.
    fn speed_ratio(&self, st: &Stage) -> f32 {
        let programmed = match st.gcode.motion.current.map(|c| c.block) {
            Some(Block::Line { feed_mm_min, .. } | Block::Arc { feed_mm_min, .. }) => {
                st.gcode.overrides.feed_mm_min(feed_mm_min) / 60.0
            }
            _ => return 0.0,
        };
        let ratio = self.speed_mm_s() / programmed.max(1e-9);
        kinematics_core::numeric::clamp(ratio, 0.0, 1.0) as f32
    }
}

/// Whether the running block lights the laser (a lit G1/G2/G3).
#[inline(never)]
fn block_lit(st: &Stage) -> bool {
    st.gcode.motion.current.is_some_and(|c| st.lights(&c.block))
}
