//! Rectangle border: four comparison-method lines.

use core::iter::FusedIterator;

use super::line::LineSteps;
use super::method::Criterion;
use crate::error::Error;
use crate::frames::BoardPoint;

/// The border of the axis-aligned rectangle with opposite corners `a` and
/// `b` (board, cm): `a → (b.x, a.y) → b → (a.x, b.y) → a`, each edge
/// interpolated by [`LineSteps`]; every corner appears once, and the path
/// closes on `a`. Exact size; no allocation; `Copy` (each next point is
/// O(1)).
#[derive(Debug, Clone, Copy)]
pub struct RectSteps {
    edges: [LineSteps; 4],
    edge: usize,
}

impl RectSteps {
    /// The border through corners `a` and `b` with moves of at most
    /// `step_cm` (cm).
    ///
    /// Errors: as [`LineSteps::new`].
    pub fn new(
        a: BoardPoint,
        b: BoardPoint,
        step_cm: f64,
        criterion: Criterion,
    ) -> Result<Self, Error> {
        let c1 = BoardPoint::new(b.x_cm, a.y_cm);
        let c3 = BoardPoint::new(a.x_cm, b.y_cm);
        let mut edges = [
            LineSteps::new(a, c1, step_cm, criterion)?,
            LineSteps::new(c1, b, step_cm, criterion)?,
            LineSteps::new(b, c3, step_cm, criterion)?,
            LineSteps::new(c3, a, step_cm, criterion)?,
        ];
        // Each later edge starts on the previous edge's last point.
        for e in edges.iter_mut().skip(1) {
            e.next();
        }
        Ok(Self { edges, edge: 0 })
    }
}

impl Iterator for RectSteps {
    type Item = BoardPoint;

    fn next(&mut self) -> Option<BoardPoint> {
        while let Some(e) = self.edges.get_mut(self.edge) {
            if let Some(p) = e.next() {
                return Some(p);
            }
            self.edge += 1;
        }
        None
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self
            .edges
            .iter()
            .skip(self.edge)
            .map(ExactSizeIterator::len)
            .sum();
        (n, Some(n))
    }
}

impl ExactSizeIterator for RectSteps {}
impl FusedIterator for RectSteps {}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    #[test]
    fn border_visits_every_lattice_point_once_and_closes() {
        let a = BoardPoint::new(-2.0, -1.0);
        let b = BoardPoint::new(2.0, 1.0);
        let r = RectSteps::new(a, b, 1.0, Criterion::Midpoint).unwrap();
        assert_eq!(r.len(), 13);
        let v: Vec<_> = r.map(|p| (p.x_cm, p.y_cm)).collect();
        let expect = [
            (-2.0, -1.0),
            (-1.0, -1.0),
            (0.0, -1.0),
            (1.0, -1.0),
            (2.0, -1.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (-1.0, 1.0),
            (-2.0, 1.0),
            (-2.0, 0.0),
            (-2.0, -1.0),
        ];
        assert_eq!(v, expect);
    }

    #[test]
    fn uneven_sides_end_on_each_corner() {
        let a = BoardPoint::new(0.3, 0.1);
        let b = BoardPoint::new(-1.2, 2.45);
        let v: Vec<_> = RectSteps::new(a, b, 0.5, Criterion::Seed)
            .unwrap()
            .collect();
        for corner in [BoardPoint::new(-1.2, 0.1), b, BoardPoint::new(0.3, 2.45)] {
            assert_eq!(v.iter().filter(|&&p| p == corner).count(), 1, "{corner:?}");
        }
        assert_eq!(v.first(), Some(&a));
        assert_eq!(v.last(), Some(&a));
    }

    #[test]
    fn invalid_input() {
        let a = BoardPoint::new(0.0, 0.0);
        assert!(RectSteps::new(a, BoardPoint::new(f64::NAN, 1.0), 1.0, Criterion::Seed).is_err());
        assert!(RectSteps::new(a, a, 0.0, Criterion::Seed).is_err());
        // A zero-size rectangle is its one corner.
        let v: Vec<_> = RectSteps::new(a, a, 1.0, Criterion::Seed)
            .unwrap()
            .collect();
        assert_eq!(v, [a]);
    }
}
