//! [`StrokeCm`]: one stroke of straight lines in board cm, compact enough
//! to travel in a galvo request (a start and up to four line ends in
//! `f32`: a figure 8 bytes bigger than a circle).
//!
//! Lines only: an arc segment costs the galvo's prep stage ~35 000 M4
//! instructions of `f64` set-up (bench-m4 measured a stroke of four
//! half-turn arcs at 216 000 instructions, 2.6× the 640 µs a prepared
//! step may take, and 331 instructions per sample across its arc
//! junctions, over the 2 µs budget), so G-code arcs reach the galvo as
//! chords within `$12`, as before.
//!
//! A contour longer than four lines travels as several: the first, then
//! pieces marked [`StrokeCm::continuing`] it, which the galvo joins to
//! the stroke it is marking.

use super::super::point::PointCm;
use super::super::units::Unit;
use super::stroke::{STROKE_SEGMENTS, Segment, Stroke};

/// One stroke drawn without a break: from a start through up to
/// [`Self::MAX_SEGMENTS`] straight lines, board cm in `f32` (0.1 µm at
/// the board's scale).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrokeCm {
    /// Start, then each line's end, cm.
    points: [[f32; 2]; STROKE_SEGMENTS + 1],
    len: u8,
    /// Continues the stroke before it (see [`Self::continuing`]).
    continues: bool,
}

impl StrokeCm {
    /// Most lines one stroke holds (as many as the galvo's path planner
    /// loads at once).
    pub const MAX_SEGMENTS: usize = STROKE_SEGMENTS;

    /// A stroke starting at `start`, no line yet. `None` for a non-finite
    /// point.
    pub fn new(start: PointCm) -> Option<Self> {
        let mut stroke = Self {
            points: [[0.0; 2]; STROKE_SEGMENTS + 1],
            len: 0,
            continues: false,
        };
        stroke.set(0, start).then_some(stroke)
    }

    /// A stroke that continues the one sent before it, which ends at
    /// `start`: the galvo joins it to that stroke while it is still being
    /// marked (no laser off/on, no stop at the joint), and marks it as a
    /// stroke of its own when that one has already ended. `None` for a
    /// non-finite point.
    pub fn continuing(start: PointCm) -> Option<Self> {
        let mut stroke = Self::new(start)?;
        stroke.continues = true;
        Some(stroke)
    }

    /// Whether it continues the stroke before it ([`Self::continuing`]).
    pub fn continues(&self) -> bool {
        self.continues
    }

    /// Adds a line to `to`; `false` (nothing added) when full or `to` is
    /// not finite.
    pub fn line_to(&mut self, to: PointCm) -> bool {
        let next = usize::from(self.len) + 1;
        if next > STROKE_SEGMENTS || !self.set(next, to) {
            return false;
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

    /// Lines.
    pub fn segments(&self) -> usize {
        usize::from(self.len)
    }

    /// Lines still free.
    pub fn room(&self) -> usize {
        STROKE_SEGMENTS - self.segments()
    }

    /// The start, cm.
    pub fn start(&self) -> PointCm {
        let [x, y] = self.points[0];
        PointCm::new(f64::from(x), f64::from(y))
    }

    /// The start and every line's end, cm.
    pub fn points(&self) -> impl Iterator<Item = PointCm> + '_ {
        let points = self.points.get(..=self.segments()).unwrap_or_default();
        points
            .iter()
            .map(|&[x, y]| PointCm::new(f64::from(x), f64::from(y)))
    }

    /// The stroke with its points converted to `unit`.
    pub(super) fn in_unit(&self, unit: Unit) -> Stroke {
        let at = |p: PointCm| [unit.from_cm(p.x_cm), unit.from_cm(p.y_cm)];
        let mut points = self.points().map(at);
        let start = points.next().unwrap_or_default();
        Stroke::lines(start, points)
    }

    /// Lowest and highest `[x, y]` of its points in `unit`.
    pub(super) fn bounds(&self, unit: Unit) -> ([f64; 2], [f64; 2]) {
        let stroke = self.in_unit(unit);
        let ends = stroke.segments.iter().map(|s| match *s {
            Segment::Line { to } | Segment::Arc { end: to, .. } => to,
        });
        ends.fold((stroke.start, stroke.start), |(lo, hi), [x, y]| {
            ([lo[0].min(x), lo[1].min(y)], [hi[0].max(x), hi[1].max(y)])
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::Segment;
    use super::*;

    fn at(x_cm: f64, y_cm: f64) -> PointCm {
        PointCm::new(x_cm, y_cm)
    }

    #[test]
    fn a_stroke_is_its_lines_in_the_unit_asked() {
        let mut stroke = StrokeCm::new(at(-1.0, 0.5)).unwrap();
        assert!(stroke.line_to(at(2.0, 0.5)));
        assert!(stroke.line_to(at(2.0, -3.0)));
        let mm = stroke.in_unit(Unit::GalvoMm);
        assert_eq!(mm.start, [-10.0, 5.0]);
        assert_eq!(
            &mm.segments[..],
            [
                Segment::Line { to: [20.0, 5.0] },
                Segment::Line { to: [20.0, -30.0] }
            ]
        );
        assert_eq!(stroke.bounds(Unit::GalvoMm), ([-10.0, -30.0], [20.0, 5.0]));
        assert_eq!(stroke.points().count(), 3);
    }

    #[test]
    fn a_stroke_refuses_what_it_cannot_hold() {
        let mut stroke = StrokeCm::new(at(0.0, 0.0)).unwrap();
        assert!(!stroke.line_to(at(f64::NAN, 0.0)));
        for k in 0..StrokeCm::MAX_SEGMENTS {
            assert!(stroke.line_to(at(k as f64, 1.0)));
        }
        assert!(!stroke.line_to(at(9.0, 9.0)), "full");
        assert_eq!(stroke.segments(), StrokeCm::MAX_SEGMENTS);
        assert_eq!(stroke.room(), 0);
        assert!(StrokeCm::new(at(f64::INFINITY, 0.0)).is_none());
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
        // A circle figure is 40 B: the stroke adds at most 8 B.
        assert!(figure <= 48 && request <= 64, "{figure} B, {request} B");
    }
}
