//! The per-sample side: freezing the head block's profile and evaluating
//! it at the sample instants in `f32`.

use super::block::{Geometry, IDLE_EXEC, first_sample_after, trapezoid};
use super::{ArcRotor, BlockEnd, MarkSample, PathPlanner};
use kinematics_core::numeric::clamp;

impl<const CAP: usize> PathPlanner<CAP> {
    /// Freezes the head block's profile. `base` is the time of the last
    /// emitted sample relative to the block start (≤ 0). Once per block,
    /// in `f64`: kept out of line, out of the per-sample path.
    #[inline(never)]
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

    /// Prepares the first block for sampling ahead of time (its speed
    /// profile, sample indices and, for an arc, the start direction: the
    /// f64 work [`Self::next_sample`] would otherwise do on its first
    /// call), so the first sample costs what every other does. A no-op
    /// when a block already runs or the head is a jump or there is none;
    /// the samples are the same either way. For the prep stage, once the
    /// stroke is loaded.
    pub fn prime(&mut self) {
        if self.exec.active {
            return;
        }
        match self.block(0) {
            Some(b) if !b.is_jump() => {
                self.freeze_head(0.0);
            }
            _ => {}
        }
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
