//! What the planner's blocks carry (one segment each: its geometry) and
//! the running block's frozen `f32` profile.

use super::rotor::ArcRotor;
use kinematics_core::numeric::clamp;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Geometry {
    Line {
        start: [f64; 2],
        unit: [f64; 2],
    },
    Arc {
        center: [f64; 2],
        radius: f64,
        start_angle: f64,
        /// +1 counter-clockwise, −1 clockwise.
        dir: f64,
    },
    Jump {
        from: [f64; 2],
        to: [f64; 2],
    },
}

/// What a planner block carries beside its planned speeds: its geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Shape {
    pub(super) geom: Geometry,
    pub(super) end: [f64; 2],
    /// First block after a jump or of the very first path: enters at rest.
    pub(super) starts_path: bool,
}

impl Shape {
    pub(super) fn is_jump(&self) -> bool {
        matches!(self.geom, Geometry::Jump { .. })
    }

    /// Whether the block follows the one before without a stop (its
    /// entry is the one before's exit).
    pub(super) fn continues_path(&self) -> bool {
        !self.is_jump() && !self.starts_path
    }
}

/// The running block's frozen profile, in `f32` for the per-sample path.
///
/// Sample `j` of the block (j = 1, 2, …) is at time `base + j·Ts` from the
/// block start. To keep `f32` time arithmetic exact enough over long blocks,
/// the phase of sample `j` is decided by integer compares against the
/// first sample index of each phase (`j_cruise`, `j_decel`, `j_end`,
/// computed in `f64` at freeze time), and times inside a phase are
/// `offset + (j − j_phase)·Ts` with a small `offset ∈ (0, Ts]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Exec {
    pub(super) active: bool,
    pub(super) arc: bool,
    pub(super) p0: [f32; 2],
    pub(super) unit: [f32; 2],
    pub(super) radius: f32,
    /// `dir / radius`: turn (rad) per mm of arc, signed.
    pub(super) turn_per_mm: f32,
    /// Direction from the centre at the last emitted sample.
    pub(super) rotor: ArcRotor,
    /// Path distance of the last emitted sample in this block, mm.
    pub(super) s_prev: f32,
    pub(super) end: [f32; 2],
    pub(super) length: f32,
    pub(super) v0: f32,
    pub(super) vp: f32,
    pub(super) v1: f32,
    pub(super) accel: f32,
    pub(super) d_acc: f32,
    pub(super) t_dec: f32,
    /// Sample period, s (f32 copy: no f64 per sample).
    pub(super) ts: f32,
    /// `base` as f32 (acceleration phase times are small).
    pub(super) base: f32,
    /// First sample index in the cruise / deceleration phase / after the end.
    pub(super) j_cruise: u32,
    pub(super) j_decel: u32,
    pub(super) j_end: u32,
    /// Time of sample `j_cruise` after the end of acceleration, of sample
    /// `j_decel` after the start of deceleration (both in (0, Ts]).
    pub(super) off_cruise: f32,
    pub(super) off_decel: f32,
    /// Samples emitted in this block.
    pub(super) k: u32,
    /// `base` and the block duration in f64, for the carry into the next
    /// block.
    pub(super) base64: f64,
    pub(super) t_total64: f64,
    /// The block's planned entry speed, mm/s (f64, diagnostics).
    pub(super) entry64: f64,
}

pub(super) const IDLE_EXEC: Exec = Exec {
    active: false,
    arc: false,
    p0: [0.0; 2],
    unit: [0.0; 2],
    ts: 0.0,
    radius: 0.0,
    turn_per_mm: 0.0,
    rotor: ArcRotor::UNIT_X,
    s_prev: 0.0,
    end: [0.0; 2],
    length: 0.0,
    v0: 0.0,
    vp: 0.0,
    v1: 0.0,
    accel: 0.0,
    d_acc: 0.0,
    t_dec: 0.0,
    base: 0.0,
    j_cruise: 0,
    j_decel: 0,
    j_end: 0,
    off_cruise: 0.0,
    off_decel: 0.0,
    k: 0,
    base64: 0.0,
    t_total64: 0.0,
    entry64: 0.0,
};

/// First sample index `j ≥ 1` with `base + j·ts > t` and the time of that
/// sample after `t`.
pub(super) fn first_sample_after(base: f64, ts: f64, t: f64) -> (u32, f32) {
    let j = libm::floor((t - base) / ts) + 1.0;
    let j = j.max(1.0);
    // Saturating conversion (blocks longer than 2³² samples are absurd).
    let ju = j as u32;
    (ju, (base + f64::from(ju) * ts - t) as f32)
}

/// Trapezoidal speed profile over `l` from `v0` to `v1` with cap `vn` and
/// acceleration `a`: `(v_peak, d_acc, t_acc, t_cruise, t_dec)`.
pub(super) fn trapezoid(v0: f64, v1: f64, vn: f64, a: f64, l: f64) -> (f64, f64, f64, f64, f64) {
    let d_acc_full = (vn * vn - v0 * v0) / (2.0 * a);
    let d_dec_full = (vn * vn - v1 * v1) / (2.0 * a);
    if d_acc_full + d_dec_full <= l {
        let t_cruise = (l - d_acc_full - d_dec_full) / vn;
        (vn, d_acc_full, (vn - v0) / a, t_cruise, (vn - v1) / a)
    } else {
        let vp = libm::sqrt(0.5 * (2.0 * a * l + v0 * v0 + v1 * v1))
            .max(v0)
            .max(v1);
        let d_acc = clamp((vp * vp - v0 * v0) / (2.0 * a), 0.0, l);
        (vp, d_acc, (vp - v0) / a, 0.0, (vp - v1) / a)
    }
}
