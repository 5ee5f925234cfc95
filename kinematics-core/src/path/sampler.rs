//! Uniform arc-length sampling of lines and arcs with a chord-error bound.

use core::f64::consts::TAU;
use core::iter::FusedIterator;

use super::method::{MAX_STEPS, Rotation};
use crate::error::Error;
use crate::frames::BoardPoint;
use crate::numeric::{finite, trig};

/// A path segment in the board plane (cm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Segment {
    /// Straight line.
    Line {
        /// Start, cm.
        from: BoardPoint,
        /// End, cm.
        to: BoardPoint,
    },
    /// Circular arc about `centre` from `start` to `end` in direction
    /// `rotation`; `start == end` is a full circle.
    Arc {
        /// Start (on the circle), cm.
        start: BoardPoint,
        /// End, cm (within the chord tolerance of the circle).
        end: BoardPoint,
        /// Centre, cm.
        centre: BoardPoint,
        /// Direction of travel.
        rotation: Rotation,
    },
}

/// Points along a segment at equal arc-length spacing: the start point,
/// then `n` more, the last exactly the end point. The spacing is the
/// largest that is ≤ `max_step_cm` and keeps every chord within
/// `max_chord_error_cm` of the arc (sagitta `R·(1 − cos(Δφ/2))`). Every
/// point lies on the ideal path (the end point within the tolerance).
/// Exact size; no allocation.
#[derive(Debug, Clone)]
pub struct UniformSampler {
    shape: Shape,
    start: BoardPoint,
    end: BoardPoint,
    n: u32,
    k: u32,
}

/// A board line or arc evaluated by the fraction of its length: the one
/// point-at-parameter shared by the gimbal's sampler and the stepper's
/// piece cutting.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Straight line.
    Line {
        /// Start, cm.
        from: BoardPoint,
        /// End, cm.
        to: BoardPoint,
    },
    /// Circular arc.
    Arc {
        /// Centre, cm.
        centre: BoardPoint,
        /// Radius (centre to start), cm.
        radius_cm: f64,
        /// Angle of the start about the centre, rad.
        start_rad: f64,
        /// Signed sweep, radians (negative clockwise).
        sweep_rad: f64,
    },
}

impl Shape {
    /// The shape of `segment`; an arc whose end is its start (or within
    /// 1e-12 rad of it, ahead in its direction) is a full circle.
    pub fn of(segment: Segment) -> Self {
        match segment {
            Segment::Line { from, to } => Shape::Line { from, to },
            Segment::Arc {
                start,
                end,
                centre,
                rotation,
            } => {
                let (ax, ay) = (start.x_cm - centre.x_cm, start.y_cm - centre.y_cm);
                let start_rad = libm::atan2(ay, ax);
                let a = rotation.sign()
                    * (libm::atan2(end.y_cm - centre.y_cm, end.x_cm - centre.x_cm) - start_rad);
                let a = a - TAU * libm::floor(a / TAU);
                let sweep = if start == end || a < 1e-12 { TAU } else { a };
                Shape::Arc {
                    centre,
                    radius_cm: crate::numeric::hypot(ax, ay),
                    start_rad,
                    sweep_rad: rotation.sign() * sweep,
                }
            }
        }
    }

    /// The point a fraction `t` (0..=1) along the shape, cm.
    pub fn point_at(&self, t: f64) -> BoardPoint {
        match *self {
            Shape::Line { from, to } => BoardPoint {
                x_cm: from.x_cm + t * (to.x_cm - from.x_cm),
                y_cm: from.y_cm + t * (to.y_cm - from.y_cm),
            },
            Shape::Arc {
                centre,
                radius_cm,
                start_rad,
                sweep_rad,
            } => {
                let (s, c) = trig::sin_cos(start_rad + t * sweep_rad);
                BoardPoint {
                    x_cm: centre.x_cm + radius_cm * c,
                    y_cm: centre.y_cm + radius_cm * s,
                }
            }
        }
    }
}

impl UniformSampler {
    /// Samples `segment` with spacing ≤ `max_step_cm` and chord error
    /// ≤ `max_chord_error_cm` (both cm, > 0).
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`] (step or
    /// tolerance ≤ 0), [`Error::EndNotOnCircle`] (arc end off the circle by
    /// more than the tolerance), [`Error::TooManySteps`].
    pub fn new(segment: Segment, max_step_cm: f64, max_chord_error_cm: f64) -> Result<Self, Error> {
        if finite(max_step_cm, "max_step_cm")? <= 0.0
            || finite(max_chord_error_cm, "max_chord_error_cm")? <= 0.0
        {
            return Err(Error::InvalidConfig {
                what: "sampler step and chord error must be > 0",
            });
        }
        let (shape, start, end, n_f) = match segment {
            Segment::Line { from, to } => {
                from.check_finite()?;
                to.check_finite()?;
                let len = crate::numeric::hypot(to.x_cm - from.x_cm, to.y_cm - from.y_cm);
                (
                    Shape::Line { from, to },
                    from,
                    to,
                    libm::ceil(len / max_step_cm),
                )
            }
            Segment::Arc {
                start,
                end,
                centre,
                rotation: _,
            } => {
                start.check_finite()?;
                end.check_finite()?;
                centre.check_finite()?;
                let shape = Shape::of(segment);
                let (r, r_end) = (
                    crate::numeric::hypot(start.x_cm - centre.x_cm, start.y_cm - centre.y_cm),
                    crate::numeric::hypot(end.x_cm - centre.x_cm, end.y_cm - centre.y_cm),
                );
                if !r.is_finite() || !r_end.is_finite() {
                    return Err(Error::TooManySteps);
                }
                if (r_end - r).abs() > max_chord_error_cm {
                    return Err(Error::EndNotOnCircle);
                }
                let sweep = match shape {
                    Shape::Arc { sweep_rad, .. } => sweep_rad.abs(),
                    Shape::Line { .. } => 0.0,
                };
                // Largest angle whose chord stays within the tolerance, and
                // whose arc is at most one step.
                let cos_half = (1.0 - max_chord_error_cm / r).max(-1.0);
                let by_chord = 2.0 * trig::acos(cos_half);
                let by_step = max_step_cm / r;
                let dphi = by_chord.min(by_step);
                let n_f = if r == 0.0 || sweep == 0.0 {
                    0.0
                } else {
                    libm::ceil(sweep / dphi)
                };
                (shape, start, end, n_f)
            }
        };
        if !n_f.is_finite() || n_f > f64::from(MAX_STEPS) {
            return Err(Error::TooManySteps);
        }
        Ok(Self {
            shape,
            start,
            end,
            // In 0..=MAX_STEPS: exact; a zero-length segment is one point.
            n: (n_f as u32).max(1),
            k: 0,
        })
    }

    /// Number of intervals (points after the start point).
    pub fn intervals(&self) -> u32 {
        self.n
    }

    fn at(&self, k: u32) -> BoardPoint {
        if k == 0 {
            return self.start;
        }
        if k >= self.n {
            return self.end;
        }
        self.shape.point_at(f64::from(k) / f64::from(self.n))
    }
}

impl Iterator for UniformSampler {
    type Item = BoardPoint;

    fn next(&mut self) -> Option<BoardPoint> {
        if self.k > self.n {
            return None;
        }
        let p = self.at(self.k);
        self.k += 1;
        Some(p)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = (self.n + 1).saturating_sub(self.k) as usize;
        (left, Some(left))
    }
}

impl ExactSizeIterator for UniformSampler {}
impl FusedIterator for UniformSampler {}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use core::f64::consts::PI;
    use proptest::prelude::*;
    use std::vec::Vec;

    fn dist(a: BoardPoint, b: BoardPoint) -> f64 {
        crate::numeric::hypot(a.x_cm - b.x_cm, a.y_cm - b.y_cm)
    }

    #[test]
    fn line_hand_computed() {
        let seg = Segment::Line {
            from: BoardPoint::new(0.0, 0.0),
            to: BoardPoint::new(3.0, 4.0),
        };
        // Length 5, step ≤ 2 → 3 intervals of 5/3.
        let v: Vec<_> = UniformSampler::new(seg, 2.0, 0.01).unwrap().collect();
        assert_eq!(v.len(), 4);
        assert!((v[1].x_cm - 1.0).abs() < 1e-15 && (v[1].y_cm - 4.0 / 3.0).abs() < 1e-15);
        assert_eq!(v[3], BoardPoint::new(3.0, 4.0));
    }

    #[test]
    fn circle_spacing_from_the_chord_bound() {
        // R = 10, tolerance 0.1: Δφ ≤ 2·acos(0.99) = 0.2838 rad → 23 intervals.
        let c = BoardPoint::new(0.0, 0.0);
        let a = BoardPoint::new(10.0, 0.0);
        let seg = Segment::Arc {
            start: a,
            end: a,
            centre: c,
            rotation: Rotation::Ccw,
        };
        let s = UniformSampler::new(seg, 100.0, 0.1).unwrap();
        let expect = libm::ceil(TAU / (2.0 * libm::acos(0.99))) as u32;
        assert_eq!(s.intervals(), expect);
        assert_eq!(expect, 23);
        let v: Vec<_> = s.collect();
        assert_eq!(v.first(), Some(&a));
        assert_eq!(v.last(), Some(&a));
        // Counter-clockwise: the second point is above the x axis.
        assert!(v[1].y_cm > 0.0);
    }

    #[test]
    fn errors() {
        let p = BoardPoint::new(0.0, 0.0);
        let line = Segment::Line { from: p, to: p };
        assert!(matches!(
            UniformSampler::new(line, 0.0, 0.1),
            Err(Error::InvalidConfig { .. })
        ));
        assert!(matches!(
            UniformSampler::new(line, 1.0, f64::NAN),
            Err(Error::NonFinite { .. })
        ));
        let far = Segment::Line {
            from: p,
            to: BoardPoint::new(1e12, 0.0),
        };
        assert_eq!(
            UniformSampler::new(far, 1e-3, 0.1).err(),
            Some(Error::TooManySteps)
        );
        let off = Segment::Arc {
            start: BoardPoint::new(1.0, 0.0),
            end: BoardPoint::new(0.0, 1.5),
            centre: p,
            rotation: Rotation::Cw,
        };
        assert_eq!(
            UniformSampler::new(off, 0.1, 0.1).err(),
            Some(Error::EndNotOnCircle)
        );
        // A zero-length line is its one point (start and end).
        let v: Vec<_> = UniformSampler::new(line, 1.0, 0.1).unwrap().collect();
        assert_eq!(v, [p, p]);
    }

    proptest! {
        #[test]
        fn arcs_are_uniform_on_path_and_within_the_chord_bound(
            cx in -10.0f64..10.0, cy in -10.0f64..10.0, r in 0.5f64..50.0,
            a0 in -PI..PI, a1 in -PI..PI, ccw: bool, step in 0.05f64..5.0, tol in 0.001f64..0.5,
        ) {
            let c = BoardPoint::new(cx, cy);
            let at = |a: f64| BoardPoint::new(cx + r * libm::cos(a), cy + r * libm::sin(a));
            let rotation = if ccw { Rotation::Ccw } else { Rotation::Cw };
            let seg = Segment::Arc { start: at(a0), end: at(a1), centre: c, rotation };
            let v: Vec<_> = UniformSampler::new(seg, step, tol).unwrap().collect();
            prop_assert_eq!(v[0], at(a0));
            prop_assert_eq!(*v.last().unwrap(), at(a1));
            let chord0 = dist(v[0], v[1]);
            for w in v.windows(2) {
                // On the circle, equal chords, arc ≤ step, sagitta ≤ tol.
                prop_assert!((dist(w[1], c) - r).abs() < 1e-9);
                let chord = dist(w[0], w[1]);
                prop_assert!((chord - chord0).abs() < 1e-9);
                let dphi = 2.0 * libm::asin((chord / (2.0 * r)).min(1.0));
                prop_assert!(r * dphi <= step + 1e-9);
                let sagitta = r - libm::sqrt((r * r - chord * chord / 4.0).max(0.0));
                prop_assert!(sagitta <= tol + 1e-9);
                // Travel direction: the cross product sign follows the rotation.
                let cross = (w[0].x_cm - cx) * (w[1].y_cm - cy) - (w[0].y_cm - cy) * (w[1].x_cm - cx);
                let turns_right_way = if ccw { cross >= -1e-9 } else { cross <= 1e-9 };
                prop_assert!(turns_right_way);
            }
        }

        #[test]
        fn lines_are_uniform_and_on_the_line(
            x0 in -20.0f64..20.0, y0 in -20.0f64..20.0, x1 in -20.0f64..20.0, y1 in -20.0f64..20.0,
            step in 0.05f64..5.0,
        ) {
            let (a, b) = (BoardPoint::new(x0, y0), BoardPoint::new(x1, y1));
            let v: Vec<_> = UniformSampler::new(Segment::Line { from: a, to: b }, step, 0.01).unwrap().collect();
            prop_assert_eq!(v[0], a);
            prop_assert_eq!(*v.last().unwrap(), b);
            let len = dist(a, b);
            for w in v.windows(2) {
                prop_assert!(dist(w[0], w[1]) <= step + 1e-9);
                prop_assert!((dist(w[0], w[1]) - len / (v.len() - 1) as f64).abs() < 1e-9);
            }
        }
    }
}
