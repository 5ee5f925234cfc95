//! Planning the gimbal's stream: each motion block's cruise and
//! acceleration on the gimbal, and the exit speed the look-ahead plan
//! allows the block running.

use crate::grbl::{Block, PointMm};
use crate::sequencer::drivers::gimbal::deg_per_mm::DegPerMm;
use crate::sequencer::drivers::gimbal::{GIMBAL_ACCEL_DEG_S2, PLAN_BLOCKS};
use crate::sequencer::drivers::stage::Stage;
use crate::sequencer::gcode::queue::{MIN_LENGTH_MM, block_point, cm, planned_length, point_at};
use kinematics_core::lookahead::{Lookahead, SpeedCursor};

/// Unit directions at the start and at the end of a motion block of
/// `length` mm.
fn tangents(block: &Block, length: f64) -> [[f64; 2]; 2] {
    let near = (MIN_LENGTH_MM / length).max(1e-3);
    [
        unit(point_at(block, 0, 1), block_point(block, near)),
        unit(block_point(block, 1.0 - near), point_at(block, 1, 1)),
    ]
}

/// Unit direction from `a` to `b`.
fn unit(a: PointMm, b: PointMm) -> [f64; 2] {
    let d = a.distance_to(b).max(1e-12);
    [(b.x_mm - a.x_mm) / d, (b.y_mm - a.y_mm) / d]
}

/// Cruise (mm/s) and acceleration (mm/s²) of `block` on the gimbal:
/// F (G0: the rate limit) within `$110` and the servo speed, `$120`
/// within [`GIMBAL_ACCEL_DEG_S2`], through the joint degrees per mm
/// along the block.
#[inline(never)]
pub(in crate::sequencer) fn stream_limits(
    st: &Stage,
    kept: &DegPerMm<PLAN_BLOCKS>,
    block: &Block,
    length: f64,
) -> (f64, f64) {
    let s = st.settings;
    let deg_per_mm = joint_deg_per_mm(st, kept, block, length).max(1e-6);
    let cap = (s.servo_speed_deg_s / deg_per_mm).min(s.galvo.mark_speed_mm_s);
    let feed = match *block {
        Block::Line { feed_mm_min, .. }
        | Block::Arc { feed_mm_min, .. }
        | Block::Jog { feed_mm_min, .. } => feed_mm_min / 60.0,
        _ => cap,
    };
    let accel = (GIMBAL_ACCEL_DEG_S2 / deg_per_mm).min(s.galvo.mark_accel_mm_s2);
    (feed.min(cap).max(1e-3), accel.max(1e-3))
}

/// The larger joint's travel per mm along `block` (two pieces), °/mm:
/// kept since the block was queued (`kept`), or worked out.
pub(super) fn joint_deg_per_mm(
    st: &Stage,
    kept: &DegPerMm<PLAN_BLOCKS>,
    block: &Block,
    length: f64,
) -> f64 {
    match kept.get(block) {
        Some(v) => v,
        None => joint_deg_per_mm_aimed(st, block, length),
    }
}

/// [`joint_deg_per_mm`] through the aims of the block's ends and middle.
#[inline(never)]
fn joint_deg_per_mm_aimed(st: &Stage, block: &Block, length: f64) -> f64 {
    let aim = |k: u32| st.aimer.aim(cm(point_at(block, k, 2))).ok();
    let (mut yaw, mut pitch) = (0.0, 0.0);
    let mut prev = aim(0);
    for k in 1..=2 {
        let next = aim(k);
        if let (Some(a), Some(b)) = (prev, next) {
            yaw += libm::fabs(b.yaw_deg - a.yaw_deg);
            pitch += libm::fabs(b.pitch_deg - a.pitch_deg);
        }
        prev = next;
    }
    libm::fmax(yaw, pitch) / length
}

/// The exit speed the plan allows the running block (what is left of
/// it from `cursor`): its junction with the next queued motion block
/// and what lies behind that, or 0 when the next must start from rest
/// (none queued, a dwell, pause or end, a dark → lit change, or the
/// gimbal has not arrived anywhere yet: dark until it has).
#[inline(never)]
pub(in crate::sequencer) fn stream_exit_speed(
    st: &Stage,
    kept: &DegPerMm<PLAN_BLOCKS>,
    current: &Block,
    cursor: &SpeedCursor,
) -> f64 {
    let motion = &st.gcode.motion;
    let Ok(mut plan) = Lookahead::<PLAN_BLOCKS>::new(st.settings.gcode_junction_mm) else {
        return 0.0;
    };
    let left = cursor.block.length - cursor.done;
    let b = &cursor.block;
    let end_tangent = tangents(current, b.length)[1];
    if !motion.arrived
        || plan
            .push(
                left.max(MIN_LENGTH_MM),
                [end_tangent; 2],
                b.nominal_speed,
                b.accel,
            )
            .is_err()
    {
        return 0.0;
    }
    plan.limit_head_entry(cursor.speed);
    let mut lit = st.lights(current);
    for next in motion.queue.iter() {
        let Some(length) = planned_length(next) else {
            break;
        };
        let next_lit = st.lights(next);
        if next_lit && !lit {
            break;
        }
        lit = next_lit;
        let (cruise, accel) = stream_limits(st, kept, next, length);
        if plan
            .push(length, tangents(next, length), cruise, accel)
            .is_err()
        {
            break;
        }
    }
    plan.block(1)
        .filter(|n| n.max_entry_speed > 0.0)
        .map_or(0.0, |n| n.entry_speed)
}
