//! [`StrokeCm`]: one stroke of lines and arcs in board cm, compact enough
//! to travel in a galvo request (a start, up to four ends and four arc
//! sweeps in `f32`: no bigger than a circle figure plus 16 bytes).

use kinematics_core::Rotation;

use super::super::point::PointCm;
use super::super::units::Unit;
use super::{STROKE_SEGMENTS, Segment, Segments, Stroke};

/// Sweeps below this, rad, are drawn as lines (the arc would bow less
/// than 0.05 µm per mm of chord).
const LINE_SWEEP_RAD: f64 = 1e-6;

/// One stroke drawn without a break: from a start through up to
/// [`Self::MAX_SEGMENTS`] lines and circular arcs, board cm in `f32`
/// (0.1 µm at the board's scale). An arc is stored as its end and its
/// signed sweep (at most a half turn; its centre follows from the chord).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrokeCm {
    /// Start, then each segment's end, cm.
    points: [[f32; 2]; STROKE_SEGMENTS + 1],
    /// Each segment's sweep, rad: 0 for a line, positive counter-
    /// clockwise, |sweep| ≤ π.
    sweeps: [f32; STROKE_SEGMENTS],
    len: u8,
}

impl StrokeCm {
    /// Most segments one stroke holds (as many as the galvo's path
    /// planner loads at once).
    pub const MAX_SEGMENTS: usize = STROKE_SEGMENTS;

    /// A stroke starting at `start`, no segment yet. `None` for a
    /// non-finite point.
    pub fn new(start: PointCm) -> Option<Self> {
        let mut stroke = Self {
            points: [[0.0; 2]; STROKE_SEGMENTS + 1],
            sweeps: [0.0; STROKE_SEGMENTS],
            len: 0,
        };
        stroke.set(0, start).then_some(stroke)
    }

    /// Adds a line to `to`; `false` (nothing added) when full or `to` is
    /// not finite.
    pub fn line_to(&mut self, to: PointCm) -> bool {
        self.push(to, 0.0)
    }

    /// Adds an arc to `to` sweeping `sweep_rad` (positive counter-
    /// clockwise, at most a half turn: split longer arcs); `false`
    /// (nothing added) when full, or for a non-finite point or a sweep
    /// beyond a half turn.
    pub fn arc_to(&mut self, to: PointCm, sweep_rad: f64) -> bool {
        let half_turn = core::f64::consts::PI + 1e-9;
        if !(libm::fabs(sweep_rad) <= half_turn) {
            return false;
        }
        let sweep = if libm::fabs(sweep_rad) < LINE_SWEEP_RAD {
            0.0
        } else {
            sweep_rad as f32
        };
        self.push(to, sweep)
    }

    fn push(&mut self, to: PointCm, sweep: f32) -> bool {
        let k = usize::from(self.len);
        if k >= STROKE_SEGMENTS || !self.set(k + 1, to) {
            return false;
        }
        if let Some(slot) = self.sweeps.get_mut(k) {
            *slot = sweep;
        }
        self.len += 1;
        true
    }

    fn set(&mut self, index: usize, p: PointCm) -> bool {
        let xy = [p.x_cm as f32, p.y_cm as f32];
        match self.points.get_mut(index) {
            Some(slot) if xy.iter().all(|v| v.is_finite()) => {
                *slot = xy;
                true
            }
            _ => false,
        }
    }

    /// Segments.
    pub fn segments(&self) -> usize {
        usize::from(self.len)
    }

    /// Segments still free.
    pub fn room(&self) -> usize {
        STROKE_SEGMENTS - self.segments()
    }

    /// The start, cm.
    pub fn start(&self) -> PointCm {
        let [x, y] = self.points[0];
        PointCm::new(f64::from(x), f64::from(y))
    }

    /// The start and every segment's end, cm.
    pub fn points(&self) -> impl Iterator<Item = PointCm> + '_ {
        let points = self.points.get(..=self.segments()).unwrap_or_default();
        points
            .iter()
            .map(|&[x, y]| PointCm::new(f64::from(x), f64::from(y)))
    }

    /// The stroke in `unit`: its points converted first, each arc's centre
    /// computed from its converted chord (so it is equidistant from both
    /// ends in that unit).
    pub(super) fn in_unit(&self, unit: Unit) -> Stroke {
        let at = |[x, y]: [f32; 2]| [unit.from_cm(f64::from(x)), unit.from_cm(f64::from(y))];
        let start = at(self.points[0]);
        let mut from = start;
        let mut segments = Segments::new();
        for (pair, &sweep) in self
            .points
            .windows(2)
            .zip(&self.sweeps)
            .take(self.segments())
        {
            let to = at(pair[1]);
            let segment = if sweep == 0.0 {
                Segment::Line { to }
            } else {
                Segment::Arc {
                    end: to,
                    centre: centre_of(from, to, f64::from(sweep)),
                    rotation: if sweep > 0.0 {
                        Rotation::Ccw
                    } else {
                        Rotation::Cw
                    },
                }
            };
            let _ = segments.push(segment);
            from = to;
        }
        Stroke { start, segments }
    }

    /// Lowest and highest `[x, y]` in `unit` the stroke reaches: its
    /// points, and where an arc crosses the axis directions through its
    /// centre.
    pub(super) fn bounds(&self, unit: Unit) -> ([f64; 2], [f64; 2]) {
        let stroke = self.in_unit(unit);
        let (mut lo, mut hi) = (stroke.start, stroke.start);
        let mut from = stroke.start;
        for segment in &stroke.segments {
            let (end, arc) = match *segment {
                Segment::Line { to } => (to, None),
                Segment::Arc {
                    end,
                    centre,
                    rotation,
                } => (end, Some((centre, rotation))),
            };
            let mut grow = |[x, y]: [f64; 2]| {
                lo = [lo[0].min(x), lo[1].min(y)];
                hi = [hi[0].max(x), hi[1].max(y)];
            };
            grow(end);
            if let Some((c, rotation)) = arc {
                let (r, start) = polar(c, from);
                let sweep = libm::fabs(polar_sweep(start, polar(c, end).1, rotation));
                for k in 0..4 {
                    let axis = f64::from(k) * core::f64::consts::FRAC_PI_2;
                    if libm::fabs(polar_sweep(start, axis, rotation)) <= sweep {
                        let (sin, cos) = libm::sincos(axis);
                        grow([c[0] + r * cos, c[1] + r * sin]);
                    }
                }
            }
            from = end;
        }
        (lo, hi)
    }
}

/// Distance and direction (rad) of `p` from `c`.
fn polar(c: [f64; 2], p: [f64; 2]) -> (f64, f64) {
    let (dx, dy) = (p[0] - c[0], p[1] - c[1]);
    (libm::hypot(dx, dy), libm::atan2(dy, dx))
}

/// Angle turned from direction `from` to `to` (rad) in `rotation`'s
/// sense, in [0, 2π) (signed: negative clockwise).
fn polar_sweep(from: f64, to: f64, rotation: Rotation) -> f64 {
    let tau = core::f64::consts::TAU;
    let ccw = libm::fmod(libm::fmod(to - from, tau) + tau, tau);
    match rotation {
        Rotation::Ccw => ccw,
        Rotation::Cw if ccw == 0.0 => 0.0,
        Rotation::Cw => ccw - tau,
    }
}

/// Centre of the arc from `a` to `b` sweeping `sweep_rad` (positive
/// counter-clockwise, 0 < |sweep| ≤ π): on the chord's perpendicular
/// bisector, at cot(sweep/2) half chords from the midpoint.
fn centre_of(a: [f64; 2], b: [f64; 2], sweep_rad: f64) -> [f64; 2] {
    let half = [(b[0] - a[0]) / 2.0, (b[1] - a[1]) / 2.0];
    let cot = libm::cos(sweep_rad / 2.0) / libm::sin(sweep_rad / 2.0);
    [
        a[0] + half[0] - half[1] * cot,
        a[1] + half[1] + half[0] * cot,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x_cm: f64, y_cm: f64) -> PointCm {
        PointCm::new(x_cm, y_cm)
    }

    #[test]
    fn arcs_get_their_centre_back_from_the_chord_and_sweep() {
        // A quarter turn ccw about (1, 1) from (2, 1) to (1, 2), a half
        // turn cw about (1, 1) on to (1, 0), a line to the origin.
        let mut stroke = StrokeCm::new(at(2.0, 1.0)).unwrap();
        assert!(stroke.arc_to(at(1.0, 2.0), core::f64::consts::FRAC_PI_2));
        assert!(stroke.arc_to(at(1.0, 0.0), -core::f64::consts::PI));
        assert!(stroke.line_to(at(0.0, 0.0)));
        let mm = stroke.in_unit(Unit::GalvoMm);
        let centres: heapless::Vec<_, 4> = mm
            .segments
            .iter()
            .filter_map(|s| match *s {
                Segment::Arc {
                    centre, rotation, ..
                } => Some((centre, rotation)),
                Segment::Line { .. } => None,
            })
            .collect();
        let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() < 1e-5;
        assert!(close(centres[0].0, [10.0, 10.0]), "{centres:?}");
        assert_eq!(centres[0].1, Rotation::Ccw);
        assert!(close(centres[1].0, [10.0, 10.0]), "{centres:?}");
        assert_eq!(centres[1].1, Rotation::Cw);
        assert_eq!(mm.segments.last(), Some(&Segment::Line { to: [0.0, 0.0] }));
        // The half circle's far side (x = 0) and the full circle's box.
        let (lo, hi) = stroke.bounds(Unit::GalvoMm);
        assert!(
            close(lo, [0.0, 0.0]) && close(hi, [20.0, 20.0]),
            "{lo:?} {hi:?}"
        );
    }

    #[test]
    fn a_stroke_refuses_what_it_cannot_hold() {
        let mut stroke = StrokeCm::new(at(0.0, 0.0)).unwrap();
        assert!(!stroke.arc_to(at(1.0, 0.0), 4.0), "more than a half turn");
        assert!(!stroke.line_to(at(f64::NAN, 0.0)));
        for k in 0..StrokeCm::MAX_SEGMENTS {
            assert!(stroke.line_to(at(k as f64, 1.0)));
        }
        assert!(!stroke.line_to(at(9.0, 9.0)), "full");
        assert_eq!(stroke.segments(), StrokeCm::MAX_SEGMENTS);
        assert_eq!(stroke.room(), 0);
        assert!(StrokeCm::new(at(f64::INFINITY, 0.0)).is_none());
        // A vanishing sweep is a line.
        let mut stroke = StrokeCm::new(at(0.0, 0.0)).unwrap();
        assert!(stroke.arc_to(at(1.0, 0.0), 1e-9));
        assert_eq!(
            stroke.in_unit(Unit::BoardCm).segments[0],
            Segment::Line { to: [1.0, 0.0] }
        );
    }

    #[test]
    fn a_stroke_figure_stays_small_enough_to_copy_through_channels() {
        extern crate std;
        use crate::galvo::GalvoRequest;
        let (stroke, figure, request) = (
            core::mem::size_of::<StrokeCm>(),
            core::mem::size_of::<super::super::Figure>(),
            core::mem::size_of::<GalvoRequest>(),
        );
        std::eprintln!("StrokeCm {stroke} B, Figure {figure} B, GalvoRequest {request} B");
        // A circle figure is 40 B: the stroke adds at most 24 B.
        assert!(figure <= 64 && request <= 80, "{figure} B, {request} B");
    }
}
