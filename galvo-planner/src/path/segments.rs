//! Adding segments (lines, arcs, jumps) to the look-ahead plan (its
//! junction speeds and its replanning are kinematics-core's
//! [`Lookahead`](kinematics_core::lookahead::Lookahead)).

use super::block::{Geometry, Shape};
use super::{PathPlanner, finite_point, planner_error};
use crate::error::Error;
use kinematics_core::lookahead::Move;
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
        if self.len() >= CAP {
            return Err(Error::BufferFull);
        }
        let jump = Shape {
            geom: Geometry::Jump {
                from: self.pen,
                to: p,
            },
            end: p,
            starts_path: true,
        };
        self.plan
            .push_stop(jump)
            .map_err(|e| planner_error(e, 0.0))?;
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
        if self.len() >= CAP {
            return Err(Error::BufferFull);
        }
        let unit = [dx / length, dy / length];
        let shape = Shape {
            geom: Geometry::Line {
                start: self.pen,
                unit,
            },
            end: p,
            starts_path: self.next_starts_path,
        };
        let a = self.limits.accel_mm_s2;
        self.add_segment(shape, Move::new(length, [unit; 2], self.feed_mm_s, a))
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
        if self.len() >= CAP {
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
        let shape = Shape {
            geom: Geometry::Arc {
                center: c,
                radius: r0,
                start_angle: a0,
                dir,
            },
            end,
            starts_path: self.next_starts_path,
        };
        // Tangential acceleration a/√2 (the rest is centripetal); the
        // junctions are taken at a, as on lines.
        let mv = Move {
            length,
            unit_in: tangent(a0),
            unit_out: tangent(a0 + sweep),
            nominal_speed: self.feed_mm_s.min(v_cap),
            accel: a * core::f64::consts::FRAC_1_SQRT_2,
            junction_accel: a,
        };
        self.add_segment(shape, mv)
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

    fn add_segment(&mut self, shape: Shape, mv: Move) -> Result<(), Error> {
        if shape.starts_path {
            // New path: it starts at rest.
            self.plan.break_junction();
        }
        self.plan
            .push_move(mv, shape)
            .map_err(|e| planner_error(e, mv.length))?;
        self.pen = shape.end;
        self.next_starts_path = false;
        Ok(())
    }
}
