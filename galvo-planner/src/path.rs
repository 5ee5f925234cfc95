//! Path marking with look-ahead (GRBL style) in the board plane.
//!
//! Segments (lines and circular arcs, mm) are added to a fixed-capacity
//! planner buffer (`CAP ≥ 16` blocks). Each block gets a speed cap (the
//! marking speed; on arcs also `√(a·r/√2)` so the centripetal acceleration
//! stays ≤ `a/√2`) and a tangential acceleration limit (`a` on lines,
//! `a/√2` on arcs, so the total acceleration on an arc is ≤ `a`). The speed
//! at each junction is limited by GRBL's junction-deviation rule
//! `v² = a·δ·sin(θ/2)/(1 − sin(θ/2))` (θ = angle between the reversed
//! incoming and the outgoing direction) and by both blocks' caps. Every time
//! a block is added the entry speeds are recomputed by a backward pass
//! (every block can still stop at the end of the buffer) and a forward pass
//! (reachable from the previous entry speed), over the blocks not yet being
//! executed.
//!
//! Sampling: when the sampler enters a block its trapezoidal speed profile
//! is frozen (so the running block never changes under it; later blocks
//! only raise the speeds reachable behind it) and evaluated at the sample
//! instants in `f32` — a few flops per sample on lines; on arcs the spot's
//! direction from the centre turns by the sample's arc length over the
//! radius as an incremental rotation ([`ArcRotor`]: a short polynomial and
//! a renormalisation, no `sinf`/`cosf`, which compute in `f64` and cost
//! ~1 200 instructions each on the M4F). Samples are uniform in time
//! across block boundaries; a path ends with one sample exactly on its
//! end point at zero speed.
//!
//! Separate paths are joined by jumps ([`PathPlanner::move_to`]); the
//! sampler reports a jump as [`MarkSample::Jump`] and pauses, so the caller
//! can run the mirror jump (in angle space, with the laser off) with the
//! [`jump`](crate::jump) planner and [`XyIntegrator`](crate::integrator::XyIntegrator).
//! The planner works in board coordinates only; converting them to mirror
//! angles is the caller's job (galvo kinematics live in another crate).

use crate::error::{Error, positive};
use kinematics_core::numeric::{clamp, finite};

/// Limits and sample period of the path planner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarkLimits {
    /// Marking speed (and speed limit), mm/s.
    pub speed_mm_s: f64,
    /// Acceleration limit, mm/s².
    pub accel_mm_s2: f64,
    /// Junction deviation δ, mm (GRBL `$11`; 0.01 mm is GRBL's default).
    pub junction_deviation_mm: f64,
    /// Sample period, s.
    pub ts_s: f64,
}

impl MarkLimits {
    fn validate(&self) -> Result<(), Error> {
        positive(self.speed_mm_s, "speed_mm_s")?;
        positive(self.accel_mm_s2, "accel_mm_s2")?;
        let jd = finite(self.junction_deviation_mm, "junction_deviation_mm")?;
        if jd < 0.0 {
            return Err(Error::NotPositive {
                name: "junction_deviation_mm",
                value: jd,
            });
        }
        if !self.ts_s.is_finite() || self.ts_s <= 0.0 {
            return Err(Error::InvalidSamplePeriod { ts_s: self.ts_s });
        }
        Ok(())
    }
}

/// One output of the sampler.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MarkSample {
    /// Laser on: the spot position at this sample and the path speed.
    Mark {
        /// Board x, mm.
        x_mm: f32,
        /// Board y, mm.
        y_mm: f32,
        /// Speed along the path, mm/s.
        speed_mm_s: f32,
    },
    /// The next path starts elsewhere: jump there with the laser off, then
    /// keep sampling. Takes no sample period of its own.
    Jump {
        /// Where the previous path ended, mm.
        from_mm: [f64; 2],
        /// Start of the next path, mm.
        to_mm: [f64; 2],
    },
    /// Nothing queued: holding at this position (laser off).
    Idle {
        /// Board x, mm.
        x_mm: f32,
        /// Board y, mm.
        y_mm: f32,
    },
}

/// Why [`PathPlanner::fill`] stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BlockEnd {
    /// The block is full of marking samples.
    Full,
    /// A jump is due (see [`MarkSample::Jump`]); the samples before it are
    /// valid.
    Jump {
        /// Where the path ended, mm.
        from_mm: [f64; 2],
        /// Start of the next path, mm.
        to_mm: [f64; 2],
    },
    /// The buffer ran empty; the spot stopped at the last end point.
    Idle,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Geometry {
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

#[derive(Debug, Clone, Copy, PartialEq)]
struct Block {
    geom: Geometry,
    end: [f64; 2],
    length: f64,
    /// Speed cap, mm/s.
    v_nominal: f64,
    /// Tangential acceleration limit, mm/s².
    accel: f64,
    /// Junction-deviation (and caps) limit on the entry speed.
    max_entry: f64,
    /// Planned entry speed.
    entry: f64,
    /// Start and end tangents (unit).
    dir_in: [f64; 2],
    dir_out: [f64; 2],
    /// First block after a jump or of the very first path: enters at rest.
    starts_path: bool,
}

impl Block {
    fn is_jump(&self) -> bool {
        matches!(self.geom, Geometry::Jump { .. })
    }
}

const EMPTY_BLOCK: Block = Block {
    geom: Geometry::Jump {
        from: [0.0; 2],
        to: [0.0; 2],
    },
    end: [0.0; 2],
    length: 0.0,
    v_nominal: 0.0,
    accel: 0.0,
    max_entry: 0.0,
    entry: 0.0,
    dir_in: [0.0; 2],
    dir_out: [0.0; 2],
    starts_path: true,
};

/// The running block's frozen profile, in `f32` for the per-sample path.
///
/// Sample `j` of the block (j = 1, 2, …) is at time `base + j·Ts` from the
/// block start. To keep `f32` time arithmetic exact enough over long blocks,
/// the phase of sample `j` is decided by integer compares against the
/// first sample index of each phase (`j_cruise`, `j_decel`, `j_end`,
/// computed in `f64` at freeze time), and times inside a phase are
/// `offset + (j − j_phase)·Ts` with a small `offset ∈ (0, Ts]`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Exec {
    active: bool,
    arc: bool,
    p0: [f32; 2],
    unit: [f32; 2],
    radius: f32,
    /// `dir / radius`: turn (rad) per mm of arc, signed.
    turn_per_mm: f32,
    /// Direction from the centre at the last emitted sample.
    rotor: ArcRotor,
    /// Path distance of the last emitted sample in this block, mm.
    s_prev: f32,
    end: [f32; 2],
    length: f32,
    v0: f32,
    vp: f32,
    v1: f32,
    accel: f32,
    d_acc: f32,
    t_dec: f32,
    /// Sample period, s (f32 copy: no f64 per sample).
    ts: f32,
    /// `base` as f32 (acceleration phase times are small).
    base: f32,
    /// First sample index in the cruise / deceleration phase / after the end.
    j_cruise: u32,
    j_decel: u32,
    j_end: u32,
    /// Time of sample `j_cruise` after the end of acceleration, of sample
    /// `j_decel` after the start of deceleration (both in (0, Ts]).
    off_cruise: f32,
    off_decel: f32,
    /// Samples emitted in this block.
    k: u32,
    /// `base` and the block duration in f64, for the carry into the next
    /// block.
    base64: f64,
    t_total64: f64,
    /// Frozen exit speed (f64, pins the next block's entry).
    exit: f64,
}

const IDLE_EXEC: Exec = Exec {
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
    exit: 0.0,
};

/// First sample index `j ≥ 1` with `base + j·ts > t` and the time of that
/// sample after `t`.
fn first_sample_after(base: f64, ts: f64, t: f64) -> (u32, f32) {
    let j = libm::floor((t - base) / ts) + 1.0;
    let j = j.max(1.0);
    // Saturating conversion (blocks longer than 2³² samples are absurd).
    let ju = j as u32;
    (ju, (base + f64::from(ju) * ts - t) as f32)
}

/// GRBL-style look-ahead planner and sampler with room for `CAP` blocks.
///
/// `CAP` must be at least [`MIN_CAPACITY`] (checked at compile time):
///
/// ```compile_fail
/// use galvo_planner::path::{MarkLimits, PathPlanner};
/// let limits = MarkLimits { speed_mm_s: 1000.0, accel_mm_s2: 1e5, junction_deviation_mm: 0.01, ts_s: 1e-5 };
/// let _too_small = PathPlanner::<8>::new(limits, [0.0, 0.0]);
/// ```
#[derive(Debug, Clone)]
pub struct PathPlanner<const CAP: usize> {
    limits: MarkLimits,
    feed_mm_s: f64,
    blocks: [Block; CAP],
    head: usize,
    len: usize,
    /// End of the last added geometry.
    pen: [f64; 2],
    /// Whether the next segment starts a new path (after a jump / at start).
    next_starts_path: bool,
    exec: Exec,
    /// Last emitted position.
    position: [f32; 2],
}

/// The planner buffer must hold at least this many blocks.
pub const MIN_CAPACITY: usize = 16;

impl<const CAP: usize> PathPlanner<CAP> {
    const CAPACITY_OK: () = assert!(CAP >= MIN_CAPACITY, "PathPlanner needs CAP >= 16");

    /// An empty planner with the spot at rest at `start_mm`.
    pub fn new(limits: MarkLimits, start_mm: [f64; 2]) -> Result<Self, Error> {
        let () = Self::CAPACITY_OK;
        limits.validate()?;
        let start_mm = finite_point("start_mm", start_mm)?;
        Ok(Self {
            limits,
            feed_mm_s: limits.speed_mm_s,
            blocks: [EMPTY_BLOCK; CAP],
            head: 0,
            len: 0,
            pen: start_mm,
            next_starts_path: true,
            exec: IDLE_EXEC,
            position: [start_mm[0] as f32, start_mm[1] as f32],
        })
    }

    /// The limits.
    pub fn limits(&self) -> &MarkLimits {
        &self.limits
    }

    /// Marking speed for the following segments (capped at the limit).
    pub fn set_feed_mm_s(&mut self, feed_mm_s: f64) -> Result<(), Error> {
        let f = positive(feed_mm_s, "feed_mm_s")?;
        self.feed_mm_s = f.min(self.limits.speed_mm_s);
        Ok(())
    }

    /// Blocks in the buffer (including the running one).
    pub fn len(&self) -> usize {
        self.len
    }
    /// True when no block is buffered.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Free block slots.
    pub fn free_slots(&self) -> usize {
        CAP - self.len
    }
    /// End of the last added segment: where the next one starts, mm.
    pub fn pen_mm(&self) -> [f64; 2] {
        self.pen
    }
    /// Last emitted spot position, mm.
    pub fn position_mm(&self) -> [f32; 2] {
        self.position
    }
    /// True when nothing is buffered and the spot is at rest.
    pub fn is_idle(&self) -> bool {
        self.len == 0 && !self.exec.active
    }

    /// Block `i` counted from the head (`None` beyond the buffered ones).
    fn block(&self, i: usize) -> Option<&Block> {
        if i < self.len {
            self.blocks.get((self.head + i) % CAP)
        } else {
            None
        }
    }
    fn block_mut(&mut self, i: usize) -> Option<&mut Block> {
        if i < self.len {
            self.blocks.get_mut((self.head + i) % CAP)
        } else {
            None
        }
    }

    fn push(&mut self, b: Block) -> Result<(), Error> {
        if self.len >= CAP {
            return Err(Error::BufferFull);
        }
        let idx = (self.head + self.len) % CAP;
        if let Some(slot) = self.blocks.get_mut(idx) {
            *slot = b;
        }
        self.len += 1;
        Ok(())
    }

    /// Starts a new path at `p_mm`: if the spot is elsewhere a jump is
    /// queued (it uses one buffer slot).
    pub fn move_to(&mut self, p_mm: [f64; 2]) -> Result<(), Error> {
        let p = finite_point("p_mm", p_mm)?;
        if p == self.pen {
            self.next_starts_path = true;
            return Ok(());
        }
        let mut b = EMPTY_BLOCK;
        b.geom = Geometry::Jump {
            from: self.pen,
            to: p,
        };
        b.end = p;
        self.push(b)?;
        self.pen = p;
        self.next_starts_path = true;
        Ok(())
    }

    /// Marks a straight line from the pen to `p_mm` (zero-length lines are
    /// ignored).
    pub fn line_to(&mut self, p_mm: [f64; 2]) -> Result<(), Error> {
        let p = finite_point("p_mm", p_mm)?;
        let (dx, dy) = (p[0] - self.pen[0], p[1] - self.pen[1]);
        let length = libm::hypot(dx, dy);
        if length < 1e-9 {
            return Ok(());
        }
        if self.len >= CAP {
            return Err(Error::BufferFull);
        }
        let unit = [dx / length, dy / length];
        let b = Block {
            geom: Geometry::Line {
                start: self.pen,
                unit,
            },
            end: p,
            length,
            v_nominal: self.feed_mm_s,
            accel: self.limits.accel_mm_s2,
            max_entry: 0.0,
            entry: 0.0,
            dir_in: unit,
            dir_out: unit,
            starts_path: self.next_starts_path,
        };
        self.add_segment(b)
    }

    /// Marks a circular arc from the pen to `end_mm` around `center_mm`,
    /// counter-clockwise if `ccw`. `end == pen` draws a full circle. The end
    /// point must lie on the circle through the pen (tolerance
    /// max(0.005 mm, 0.1 % of the radius), as GRBL).
    pub fn arc_to(
        &mut self,
        end_mm: [f64; 2],
        center_mm: [f64; 2],
        ccw: bool,
    ) -> Result<(), Error> {
        let end = finite_point("end_mm", end_mm)?;
        let c = finite_point("center_mm", center_mm)?;
        let r0 = libm::hypot(self.pen[0] - c[0], self.pen[1] - c[1]);
        let r1 = libm::hypot(end[0] - c[0], end[1] - c[1]);
        let tol = 0.005f64.max(1e-3 * r0);
        if r0 < 1e-6 || libm::fabs(r0 - r1) > tol {
            return Err(Error::ArcRadiusMismatch {
                start_radius_mm: r0,
                end_radius_mm: r1,
            });
        }
        if self.len >= CAP {
            return Err(Error::BufferFull);
        }
        let a0 = libm::atan2(self.pen[1] - c[1], self.pen[0] - c[0]);
        let a1 = libm::atan2(end[1] - c[1], end[0] - c[0]);
        let tau = 2.0 * core::f64::consts::PI;
        let mut sweep = a1 - a0;
        let dir = if ccw { 1.0 } else { -1.0 };
        if ccw {
            while sweep <= 1e-12 {
                sweep += tau;
            }
            while sweep > tau {
                sweep -= tau;
            }
        } else {
            while sweep >= -1e-12 {
                sweep -= tau;
            }
            while sweep < -tau {
                sweep += tau;
            }
        }
        let length = r0 * libm::fabs(sweep);
        let a = self.limits.accel_mm_s2;
        let tangent = |ang: f64| [-dir * libm::sin(ang), dir * libm::cos(ang)];
        let v_cap = libm::sqrt(a * r0 * core::f64::consts::FRAC_1_SQRT_2);
        let b = Block {
            geom: Geometry::Arc {
                center: c,
                radius: r0,
                start_angle: a0,
                dir,
            },
            end,
            length,
            v_nominal: self.feed_mm_s.min(v_cap),
            accel: a * core::f64::consts::FRAC_1_SQRT_2,
            max_entry: 0.0,
            entry: 0.0,
            dir_in: tangent(a0),
            dir_out: tangent(a0 + sweep),
            starts_path: self.next_starts_path,
        };
        self.add_segment(b)
    }

    /// Adds `points[1..]` as connected lines after a `move_to(points[0])`
    /// if `new_path`; stops early when the buffer is full and returns how
    /// many points were consumed (call again with the rest after sampling).
    pub fn extend_polyline(&mut self, points: &[[f64; 2]], new_path: bool) -> Result<usize, Error> {
        let mut used = 0;
        let mut rest = points;
        if new_path {
            let Some((first, tail)) = rest.split_first() else {
                return Ok(0);
            };
            if self.free_slots() == 0 {
                return Ok(0);
            }
            self.move_to(*first)?;
            used += 1;
            rest = tail;
        }
        for p in rest {
            match self.line_to(*p) {
                Ok(()) => used += 1,
                Err(Error::BufferFull) => break,
                Err(e) => return Err(e),
            }
        }
        Ok(used)
    }

    fn add_segment(&mut self, mut b: Block) -> Result<(), Error> {
        // Junction with the previous block still in the buffer.
        let prev = if self.len > 0 {
            self.block(self.len - 1).copied()
        } else {
            None
        };
        b.max_entry = match prev {
            Some(p) if !b.starts_path && !p.is_jump() => junction_speed(
                p.dir_out,
                b.dir_in,
                self.limits.accel_mm_s2,
                self.limits.junction_deviation_mm,
            )
            .min(p.v_nominal)
            .min(b.v_nominal),
            // New path, after a jump, or everything before has been executed
            // (the spot is at rest).
            _ => 0.0,
        };
        self.push(b)?;
        self.pen = b.end;
        self.next_starts_path = false;
        self.replan();
        Ok(())
    }

    /// Backward and forward passes over the blocks not yet executing.
    fn replan(&mut self) {
        let first = usize::from(self.exec.active);
        if first >= self.len {
            return;
        }
        // The first plannable block's entry is fixed: the running block's
        // frozen exit speed, or rest.
        let fixed_entry = match self.block(first) {
            Some(b) if self.exec.active && !b.starts_path && !b.is_jump() => self.exec.exit,
            _ => 0.0,
        };
        if let Some(b) = self.block_mut(first) {
            b.entry = fixed_entry;
        }
        // Backward pass: exit of the last block is 0.
        let mut next_entry = 0.0f64;
        let mut next_connected = false;
        for i in (first..self.len).rev() {
            let Some(b) = self.block_mut(i) else { continue };
            let exit = if next_connected { next_entry } else { 0.0 };
            if i > first {
                b.entry = if b.is_jump() || b.starts_path {
                    0.0
                } else {
                    b.max_entry
                        .min(libm::sqrt(exit * exit + 2.0 * b.accel * b.length))
                };
            }
            next_entry = b.entry;
            next_connected = !b.is_jump() && !b.starts_path;
        }
        // Forward pass.
        for i in first..self.len.saturating_sub(1) {
            let (Some(cur), Some(nxt)) = (self.block(i).copied(), self.block(i + 1).copied())
            else {
                continue;
            };
            if cur.is_jump() || nxt.is_jump() || nxt.starts_path {
                continue;
            }
            let reachable = libm::sqrt(cur.entry * cur.entry + 2.0 * cur.accel * cur.length);
            if nxt.entry > reachable
                && let Some(n) = self.block_mut(i + 1)
            {
                n.entry = reachable;
            }
        }
    }

    /// Exit speed of block `i` as planned now.
    fn exit_speed(&self, i: usize) -> f64 {
        match self.block(i + 1) {
            Some(n) if !n.is_jump() && !n.starts_path => n.entry,
            _ => 0.0,
        }
    }

    /// Freezes the head block's profile. `base` is the time of the last
    /// emitted sample relative to the block start (≤ 0).
    fn freeze_head(&mut self, base: f64) {
        let Some(b) = self.block(0).copied() else {
            return;
        };
        let ts = self.limits.ts_s;
        let v0 = b.entry;
        let v1 = self.exit_speed(0);
        let (a, l, vn) = (b.accel, b.length, b.v_nominal);
        let (vp, d_acc, t_acc, t_cruise, t_dec) = trapezoid(v0, v1, vn, a, l);
        let mut e = IDLE_EXEC;
        e.active = true;
        match b.geom {
            Geometry::Line { start, unit } => {
                e.arc = false;
                e.p0 = [start[0] as f32, start[1] as f32];
                e.unit = [unit[0] as f32, unit[1] as f32];
            }
            Geometry::Arc {
                center,
                radius,
                start_angle,
                dir,
            } => {
                e.arc = true;
                e.p0 = [center[0] as f32, center[1] as f32];
                e.radius = radius as f32;
                e.turn_per_mm = (dir / radius) as f32;
                // Once per block, in f64: the exact start direction.
                e.rotor = ArcRotor::at_angle(start_angle);
            }
            Geometry::Jump { .. } => {}
        }
        e.end = [b.end[0] as f32, b.end[1] as f32];
        e.length = l as f32;
        e.ts = ts as f32;
        e.v0 = v0 as f32;
        e.vp = vp as f32;
        e.v1 = v1 as f32;
        e.accel = a as f32;
        e.d_acc = d_acc as f32;
        e.t_dec = t_dec as f32;
        e.base = base as f32;
        e.base64 = base;
        let t_total = t_acc + t_cruise + t_dec;
        e.t_total64 = t_total;
        let (jc, oc) = first_sample_after(base, ts, t_acc);
        let (jd, od) = first_sample_after(base, ts, t_acc + t_cruise);
        // Strictly after the end (a sample exactly at the end still
        // belongs to the block).
        let (je, _) = first_sample_after(base, ts, t_total);
        e.j_cruise = jc;
        e.off_cruise = oc;
        e.j_decel = jd;
        e.off_decel = od;
        e.j_end = je;
        e.k = 0;
        e.exit = v1;
        self.exec = e;
    }

    fn pop_head(&mut self) {
        if self.len > 0 {
            self.head = (self.head + 1) % CAP;
            self.len -= 1;
        }
    }

    /// Position and speed in the running block at its sample `j` (< j_end),
    /// called for j = 1, 2, … in turn (an arc's rotor advances).
    fn eval_exec(&mut self, j: u32) -> ([f32; 2], f32) {
        let e = &mut self.exec;
        let ts = e.ts;
        let (s, v) = if j < e.j_cruise {
            let tau = e.base + j as f32 * ts;
            (e.v0 * tau + 0.5 * e.accel * tau * tau, e.v0 + e.accel * tau)
        } else if j < e.j_decel {
            let tau = e.off_cruise + (j - e.j_cruise) as f32 * ts;
            (e.d_acc + e.vp * tau, e.vp)
        } else {
            // Time left until the end of the block.
            let r = (e.t_dec - (e.off_decel + (j - e.j_decel) as f32 * ts)).max(0.0);
            (
                e.length - (e.v1 * r + 0.5 * e.accel * r * r),
                e.v1 + e.accel * r,
            )
        };
        let s = clamp(s, 0.0, e.length);
        let p = if e.arc {
            // s − s_prev is exact (Sterbenz) once s ≥ s_prev/2, so the turns
            // add up to (s − 0)/r up to the rounding of each product.
            e.rotor.turn((s - e.s_prev) * e.turn_per_mm);
            e.s_prev = s;
            let [c, sn] = e.rotor.unit();
            [e.p0[0] + e.radius * c, e.p0[1] + e.radius * sn]
        } else {
            [e.p0[0] + e.unit[0] * s, e.p0[1] + e.unit[1] * s]
        };
        (p, v)
    }

    /// Advances one sample period (or reports a jump / idleness).
    pub fn next_sample(&mut self) -> MarkSample {
        let ts = self.limits.ts_s;
        let mut carry = 0.0f64;
        loop {
            if !self.exec.active {
                let Some(b) = self.block(0).copied() else {
                    return MarkSample::Idle {
                        x_mm: self.position[0],
                        y_mm: self.position[1],
                    };
                };
                if let Geometry::Jump { from, to } = b.geom {
                    self.pop_head();
                    self.position = [to[0] as f32, to[1] as f32];
                    return MarkSample::Jump {
                        from_mm: from,
                        to_mm: to,
                    };
                }
                self.freeze_head(carry);
                self.replan();
            }
            let e = self.exec;
            let j = e.k.saturating_add(1);
            if j < e.j_end {
                self.exec.k = j;
                let (p, v) = self.eval_exec(j);
                self.position = p;
                return MarkSample::Mark {
                    x_mm: p[0],
                    y_mm: p[1],
                    speed_mm_s: v,
                };
            }
            // This sample lies beyond the running block: carry on into the
            // next block if one is connected (its entry equals our exit),
            // else the path ends here.
            let continues = self
                .block(1)
                .is_some_and(|n| !n.is_jump() && !n.starts_path);
            self.pop_head();
            self.exec.active = false;
            if !continues {
                // Path end: one sample exactly on the end point, at rest.
                self.position = e.end;
                return MarkSample::Mark {
                    x_mm: e.end[0],
                    y_mm: e.end[1],
                    speed_mm_s: 0.0,
                };
            }
            carry = e.base64 + f64::from(e.k) * ts - e.t_total64;
        }
    }

    /// Fills `out` with marking samples `[x_mm, y_mm]` until it is full, a
    /// jump is due or the buffer runs empty. Returns the number written and
    /// why it stopped.
    pub fn fill(&mut self, out: &mut [[f32; 2]]) -> (usize, BlockEnd) {
        for (n, slot) in out.iter_mut().enumerate() {
            match self.next_sample() {
                MarkSample::Mark { x_mm, y_mm, .. } => *slot = [x_mm, y_mm],
                MarkSample::Jump { from_mm, to_mm } => {
                    return (n, BlockEnd::Jump { from_mm, to_mm });
                }
                MarkSample::Idle { .. } => return (n, BlockEnd::Idle),
            }
        }
        (out.len(), BlockEnd::Full)
    }

    /// Planned entry speeds of the buffered blocks (diagnostics), mm/s.
    pub fn entry_speeds(&self) -> impl Iterator<Item = f64> + '_ {
        (0..self.len).filter_map(|i| self.block(i).map(|b| b.entry))
    }
}

/// A unit vector `(cos φ, sin φ)` turned step by step in `f32` on the FPU:
/// each turn is a rotation by a polynomial `(cos δ, sin δ)` followed by a
/// renormalisation, so neither the length nor (beyond rounding) the angle
/// drifts. Per turn: about 20 multiply-adds, no library call.
///
/// Accuracy (tests): over a full circle at 1 m/s and 100 kHz (26 000
/// turns at r = 40 mm, 158 000 at r = 250 mm) the direction stays within
/// 3e-5 rad of the `f64` angle, i.e. 0.9 µm and 4.5 µm on the board
/// (a DAC LSB is 85 µm); each arc block starts from its exact angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcRotor {
    c: f32,
    s: f32,
}

/// Largest turn evaluated by the polynomial directly, rad; larger turns
/// are halved first and the result doubled back.
const ROTOR_DIRECT_MAX_RAD: f32 = 0.5;

impl ArcRotor {
    /// Pointing along +x (φ = 0).
    pub const UNIT_X: ArcRotor = ArcRotor { c: 1.0, s: 0.0 };

    /// Pointing at `angle_rad` (computed in `f64`, once).
    pub fn at_angle(angle_rad: f64) -> Self {
        let (s, c) = libm::sincos(angle_rad);
        ArcRotor {
            c: c as f32,
            s: s as f32,
        }
    }

    /// `(cos φ, sin φ)`.
    #[inline]
    pub fn unit(&self) -> [f32; 2] {
        [self.c, self.s]
    }

    /// Turns by `delta_rad` (counter-clockwise positive). A non-finite
    /// turn leaves the rotor where it is.
    #[inline]
    pub fn turn(&mut self, delta_rad: f32) {
        if !delta_rad.is_finite() {
            return;
        }
        let (c, s) = cos_sin_small(delta_rad);
        let x = self.c * c - self.s * s;
        let y = self.s * c + self.c * s;
        // One Newton step for 1/√(x² + y²) about 1: the length error goes
        // from ε to about (3/8)·ε².
        let scale = 1.5 - 0.5 * (x * x + y * y);
        self.c = x * scale;
        self.s = y * scale;
    }
}

/// `(cos δ, sin δ)` by Taylor polynomials (error < 1e-9 for |δ| ≤ 0.5);
/// larger |δ| are halved (at most 4 times for |δ| ≤ 2π, more only for
/// absurd input) and doubled back with the double-angle formulas.
#[inline]
fn cos_sin_small(delta: f32) -> (f32, f32) {
    let mut d = delta;
    let mut halvings = 0u32;
    while !(-ROTOR_DIRECT_MAX_RAD..=ROTOR_DIRECT_MAX_RAD).contains(&d) && halvings < 64 {
        d *= 0.5;
        halvings += 1;
    }
    let d2 = d * d;
    // sin: d − d³/6 + d⁵/120 − d⁷/5040; cos: 1 − d²/2 + d⁴/24 − d⁶/720 + d⁸/40320.
    let sin = d * (1.0 + d2 * (-1.0 / 6.0 + d2 * (1.0 / 120.0 + d2 * (-1.0 / 5040.0))));
    let cos = 1.0 + d2 * (-0.5 + d2 * (1.0 / 24.0 + d2 * (-1.0 / 720.0 + d2 * (1.0 / 40320.0))));
    let (mut c, mut s) = (cos, sin);
    for _ in 0..halvings {
        (c, s) = (c * c - s * s, 2.0 * s * c);
    }
    (c, s)
}

fn finite_point(name: &'static str, p: [f64; 2]) -> Result<[f64; 2], Error> {
    finite(p[0], name)?;
    finite(p[1], name)?;
    Ok(p)
}

/// GRBL's junction speed for unit directions `a` (incoming) and `b`
/// (outgoing): `v² = acc·δ·sin(θ/2)/(1 − sin(θ/2))` with
/// `cos θ = −a·b`; a reversal gives 0, a straight continuation no limit.
pub fn junction_speed(a: [f64; 2], b: [f64; 2], accel_mm_s2: f64, deviation_mm: f64) -> f64 {
    let cos_theta = -(a[0] * b[0] + a[1] * b[1]);
    if cos_theta > 0.999_999 {
        0.0
    } else if cos_theta < -0.999_999 {
        f64::INFINITY
    } else {
        let sin_half = libm::sqrt(0.5 * (1.0 - cos_theta));
        libm::sqrt(accel_mm_s2 * deviation_mm * sin_half / (1.0 - sin_half))
    }
}

/// Trapezoidal speed profile over `l` from `v0` to `v1` with cap `vn` and
/// acceleration `a`: `(v_peak, d_acc, t_acc, t_cruise, t_dec)`.
fn trapezoid(v0: f64, v1: f64, vn: f64, a: f64, l: f64) -> (f64, f64, f64, f64, f64) {
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

#[cfg(test)]
mod tests;
