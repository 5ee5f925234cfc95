//! Path interpolation in the board plane (cm): the seed's point-by-point
//! comparison method for lines, circles/arcs and rectangles, and a uniform
//! arc-length sampler with a chord-error bound. All are allocation-free
//! iterators of [`BoardPoint`](crate::frames::BoardPoint)s that start on the
//! start point and end exactly on the end point.
//!
//! # Point-by-point comparison (逐点比较法)
//!
//! Every move is one unit step along one axis. The axis is chosen, per
//! quadrant, by the sign of the deviation function (line:
//! `F = y·Xe − x·Ye`; circle: `F = x² + y² − R²`). [`Criterion`] picks
//! where F is evaluated:
//!
//! * [`Criterion::Seed`] — at the current point, exactly the seed's C code.
//!   Points stay within one step of the ideal path (the method's classical
//!   bound), e.g. the line (0,0)→(10,1) visits (1,1), 0.9 step above it.
//! * [`Criterion::Midpoint`] (default) — at the midpoint of the two
//!   candidate points. Same moves, same quadrant logic, but it always
//!   takes the candidate nearer the path: every point is within **half a
//!   step per axis** (Chebyshev distance ≤ ½ step) of the ideal path. No
//!   one-axis-per-move staircase can do better: on a 45° line the first
//!   move must go to (1,0) or (0,1), both ½ step per axis (0.71 step
//!   perpendicular) off the line.

mod circle;
mod line;
mod method;
mod rect;
mod sampler;

pub use circle::ArcSteps;
pub use line::LineSteps;
pub use method::{Criterion, MAX_STEPS, Rotation};
pub use rect::RectSteps;
pub use sampler::{Segment, Shape, UniformSampler};

#[cfg(test)]
pub(crate) mod test_support {
    //! Distances to ideal paths, for the interpolation tests.
    use crate::frames::BoardPoint;

    /// Chebyshev (max-axis) distance from `p` to the segment `a`–`b`.
    pub fn cheb_to_segment(p: BoardPoint, a: BoardPoint, b: BoardPoint) -> f64 {
        // max(|dx|, |dy|) along the segment is convex in t: golden-section
        // search, then check the ends.
        let f = |t: f64| {
            let x = a.x_cm + t * (b.x_cm - a.x_cm);
            let y = a.y_cm + t * (b.y_cm - a.y_cm);
            (p.x_cm - x).abs().max((p.y_cm - y).abs())
        };
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        let g = (libm::sqrt(5.0) - 1.0) / 2.0;
        for _ in 0..200 {
            let m1 = hi - g * (hi - lo);
            let m2 = lo + g * (hi - lo);
            if f(m1) < f(m2) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        f(0.5 * (lo + hi)).min(f(0.0)).min(f(1.0))
    }

    /// Chebyshev distance from `p` to the full circle (centre `c`, radius
    /// `r`): the smallest s with the square of half-side s around `p`
    /// touching the circle, found by bisection on s.
    pub fn cheb_to_circle(p: BoardPoint, c: BoardPoint, r: f64) -> f64 {
        let (x, y) = (p.x_cm - c.x_cm, p.y_cm - c.y_cm);
        // Square [x−s, x+s] × [y−s, y+s] meets the circle iff its nearest
        // point is inside the circle and its farthest point outside.
        let meets = |s: f64| {
            let nx = if x.abs() <= s { 0.0 } else { x.abs() - s };
            let ny = if y.abs() <= s { 0.0 } else { y.abs() - s };
            let fx = x.abs() + s;
            let fy = y.abs() + s;
            crate::numeric::hypot(nx, ny) <= r && crate::numeric::hypot(fx, fy) >= r
        };
        let (mut lo, mut hi) = (0.0f64, r + crate::numeric::hypot(x, y));
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if meets(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    }
}
