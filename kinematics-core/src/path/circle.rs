//! Circle and arc interpolation by point-by-point comparison (the seed's
//! `drawcircle`, extended to arcs).

use core::f64::consts::{PI, TAU};
use core::iter::FusedIterator;

use super::method::{Criterion, MAX_STEPS, Rotation, check_step};
use crate::error::Error;
use crate::frames::BoardPoint;
use crate::numeric::finite;

/// The points of a circular arc (board, cm) in unit moves of `step_cm`
/// along one axis at a time: the start point, one point per move, and
/// finally exactly the end point. A full circle starts and ends on the
/// same point (it closes).
///
/// The moves lie on the step lattice through the start point. Each move
/// goes one step along the axis the seed's table gives for the current
/// quadrant and direction, choosing between the "inward" and the "outward"
/// move by the sign of `F = x² + y² − R²` (see [`Criterion`]). The walk
/// stops on the lattice point nearest the end point once it has swept the
/// arc (or, should it pass that point by, as soon as it passes the end's
/// angle), then adds the end point itself if it is not on the lattice.
/// No allocation; `Copy` (each next point is O(1)).
#[derive(Debug, Clone, Copy)]
pub struct ArcSteps {
    origin: BoardPoint,
    end: BoardPoint,
    step: f64,
    /// Centre relative to the origin, steps.
    cx: f64,
    cy: f64,
    /// Radius² (of the start point), steps².
    r2: f64,
    /// Current lattice point relative to the origin.
    i: i64,
    j: i64,
    end_i: i64,
    end_j: i64,
    rotation: Rotation,
    criterion: Criterion,
    /// Angle swept so far, radians (≥ 0, in the direction of travel).
    progress: f64,
    /// Angle to sweep, radians, in [0, 2π].
    sweep: f64,
    /// Angular slack for stopping on the end's lattice point, radians.
    slack: f64,
    moves_left: u32,
    state: State,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Start,
    Walk,
    End,
    Done,
}

/// Wraps an angle to (−π, π].
fn wrap_pi(a: f64) -> f64 {
    let w = a - TAU * libm::round(a / TAU);
    if w <= -PI { w + TAU } else { w }
}

impl ArcSteps {
    /// The full circle about `centre` with radius `radius_cm`, starting and
    /// ending at its top point `(cx, cy + R)` like the seed.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`] (step ≤ 0),
    /// [`Error::PathTooShort`] (radius < 1 step), [`Error::TooManySteps`].
    pub fn circle(
        centre: BoardPoint,
        radius_cm: f64,
        rotation: Rotation,
        step_cm: f64,
        criterion: Criterion,
    ) -> Result<Self, Error> {
        centre.check_finite()?;
        let top = BoardPoint::new(centre.x_cm, centre.y_cm + finite(radius_cm, "radius_cm")?);
        Self::arc(top, top, centre, rotation, step_cm, criterion)
    }

    /// The arc from `start` to `end` about `centre` in direction `rotation`
    /// (G-code G2/G3 style); `start == end` is a full circle. `end` must be
    /// on the circle through `start` within half a step.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`] (step ≤ 0),
    /// [`Error::PathTooShort`] (radius < 1 step), [`Error::EndNotOnCircle`],
    /// [`Error::TooManySteps`].
    pub fn arc(
        start: BoardPoint,
        end: BoardPoint,
        centre: BoardPoint,
        rotation: Rotation,
        step_cm: f64,
        criterion: Criterion,
    ) -> Result<Self, Error> {
        let step = check_step(step_cm)?;
        start.check_finite()?;
        end.check_finite()?;
        centre.check_finite()?;
        let (ax, ay) = (
            (start.x_cm - centre.x_cm) / step,
            (start.y_cm - centre.y_cm) / step,
        );
        let (bx, by) = (
            (end.x_cm - centre.x_cm) / step,
            (end.y_cm - centre.y_cm) / step,
        );
        let r = crate::numeric::hypot(ax, ay);
        if !r.is_finite() || !crate::numeric::hypot(bx, by).is_finite() {
            return Err(Error::TooManySteps);
        }
        if r < 1.0 {
            return Err(Error::PathTooShort);
        }
        // A full circle takes about 8·r moves.
        if 8.0 * (r + 2.0) > f64::from(MAX_STEPS) {
            return Err(Error::TooManySteps);
        }
        if (crate::numeric::hypot(bx, by) - r).abs() > 0.5 {
            return Err(Error::EndNotOnCircle);
        }
        let sweep = if start == end {
            TAU
        } else {
            let a = rotation.sign() * (libm::atan2(by, bx) - libm::atan2(ay, ax));
            a - TAU * libm::floor(a / TAU)
        };
        let to_lattice = |d_cm: f64| libm::round(d_cm / step) as i64;
        Ok(Self {
            origin: start,
            end,
            step,
            cx: -ax,
            cy: -ay,
            r2: r * r,
            i: 0,
            j: 0,
            end_i: to_lattice(end.x_cm - start.x_cm),
            end_j: to_lattice(end.y_cm - start.y_cm),
            rotation,
            criterion,
            progress: 0.0,
            sweep,
            slack: 1.0 / r,
            // Bounded in `8·(r + 2) ≤ MAX_STEPS` above.
            moves_left: libm::ceil(8.0 * (r + 2.0)) as u32,
            state: State::Start,
        })
    }

    /// Board point of a lattice point.
    fn point(&self, i: i64, j: i64) -> BoardPoint {
        BoardPoint {
            x_cm: self.origin.x_cm + i as f64 * self.step,
            y_cm: self.origin.y_cm + j as f64 * self.step,
        }
    }

    /// Deviation function at a point relative to the centre (steps).
    fn f(&self, u: f64, v: f64) -> f64 {
        u * u + v * v - self.r2
    }

    /// The next lattice point by the comparison rule.
    fn next_lattice(&self) -> (i64, i64) {
        let (u, v) = (self.i as f64 - self.cx, self.j as f64 - self.cy);
        // Seed quadrants: 1 (x > 0, y ≥ 0), 2 (x ≤ 0, y > 0),
        // 3 (x < 0, y ≤ 0), 4 (x ≥ 0, y < 0).
        let quadrant = if u > 0.0 && v >= 0.0 {
            1
        } else if u <= 0.0 && v > 0.0 {
            2
        } else if u < 0.0 && v <= 0.0 {
            3
        } else {
            4
        };
        // (inward move, outward move) per quadrant, from the seed's table.
        let (inward, outward): ((i64, i64), (i64, i64)) = match (self.rotation, quadrant) {
            (Rotation::Cw, 1) => ((0, -1), (1, 0)),
            (Rotation::Cw, 2) => ((1, 0), (0, 1)),
            (Rotation::Cw, 3) => ((0, 1), (-1, 0)),
            (Rotation::Cw, _) => ((-1, 0), (0, -1)),
            (Rotation::Ccw, 1) => ((-1, 0), (0, 1)),
            (Rotation::Ccw, 2) => ((0, -1), (-1, 0)),
            (Rotation::Ccw, 3) => ((1, 0), (0, -1)),
            (Rotation::Ccw, _) => ((0, 1), (1, 0)),
        };
        let go_in = match self.criterion {
            // Seed: clockwise moves inward when F ≥ 0, counter-clockwise
            // when F > 0, F taken at the current point.
            Criterion::Seed => {
                let f = self.f(u, v);
                match self.rotation {
                    Rotation::Cw => f >= 0.0,
                    Rotation::Ccw => f > 0.0,
                }
            }
            // F at the midpoint of the two candidates: inward when that
            // midpoint is on or outside the circle.
            Criterion::Midpoint => {
                let mu = u + 0.5 * (inward.0 + outward.0) as f64;
                let mv = v + 0.5 * (inward.1 + outward.1) as f64;
                self.f(mu, mv) >= 0.0
            }
        };
        let (di, dj) = if go_in { inward } else { outward };
        (self.i + di, self.j + dj)
    }

    /// Signed angle (direction of travel) from lattice point a to b.
    fn turn(&self, a: (i64, i64), b: (i64, i64)) -> f64 {
        let ang = |(i, j): (i64, i64)| libm::atan2(j as f64 - self.cy, i as f64 - self.cx);
        self.rotation.sign() * wrap_pi(ang(b) - ang(a))
    }
}

impl Iterator for ArcSteps {
    type Item = BoardPoint;

    fn next(&mut self) -> Option<BoardPoint> {
        match self.state {
            State::Start => {
                self.state = if self.sweep > 0.0 {
                    State::Walk
                } else {
                    State::End
                };
                Some(self.origin)
            }
            State::Walk => {
                let next = self.next_lattice();
                let progress = self.progress + self.turn((self.i, self.j), next);
                let at_end_point = next == (self.end_i, self.end_j);
                if at_end_point && progress >= self.sweep - self.slack {
                    let p = self.point(next.0, next.1);
                    self.state = if p == self.end {
                        State::Done
                    } else {
                        State::End
                    };
                    return Some(p);
                }
                if progress > self.sweep || self.moves_left == 0 {
                    self.state = State::Done;
                    return Some(self.end);
                }
                self.moves_left -= 1;
                (self.i, self.j) = next;
                self.progress = progress;
                Some(self.point(next.0, next.1))
            }
            State::End => {
                self.state = State::Done;
                Some(self.end)
            }
            State::Done => None,
        }
    }
}

impl FusedIterator for ArcSteps {}

#[cfg(test)]
mod tests;
