//! Adding segments (lines, arcs, jumps) and the look-ahead replanning of
//! the entry speeds.

use super::block::{Block, EMPTY_BLOCK, Geometry};
use super::{PathPlanner, finite_point};
use crate::error::Error;
use kinematics_core::numeric::trig;

impl<const CAP: usize> PathPlanner<CAP> {
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
        let length = kinematics_core::numeric::hypot(dx, dy);
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
        let r0 = kinematics_core::numeric::hypot(self.pen[0] - c[0], self.pen[1] - c[1]);
        let r1 = kinematics_core::numeric::hypot(end[0] - c[0], end[1] - c[1]);
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
        let tangent = |ang: f64| [-dir * trig::sin(ang), dir * trig::cos(ang)];
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
    pub(super) fn replan(&mut self) {
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
    pub(super) fn exit_speed(&self, i: usize) -> f64 {
        match self.block(i + 1) {
            Some(n) if !n.is_jump() && !n.starts_path => n.entry,
            _ => 0.0,
        }
    }
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
