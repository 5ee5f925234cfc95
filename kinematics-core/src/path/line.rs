//! Line interpolation by point-by-point comparison (the seed's `drawline`).

use core::iter::FusedIterator;

use super::method::{Criterion, MAX_STEPS, check_step};
use crate::error::Error;
use crate::frames::BoardPoint;

/// The points of a line from `start` to `end` (board, cm) in unit moves of
/// at most `step_cm` along one axis at a time: the start point, then one
/// point per move, the last exactly `end`.
///
/// Each axis takes `⌈|Δ| / step⌉` moves of equal length (≤ `step_cm`), so
/// the staircase ends exactly on `end` with integer arithmetic for the
/// deviation function `F = j·nx − i·ny` (moves `i` of `nx` along x, `j` of
/// `ny` along y, in the line's quadrant). Exact size; no allocation;
/// `Copy`, so a caller can keep the interpolation state in plain data
/// (each next point is O(1)).
#[derive(Debug, Clone, Copy)]
pub struct LineSteps {
    start: BoardPoint,
    end: BoardPoint,
    nx: u32,
    ny: u32,
    i: u32,
    j: u32,
    f: i64,
    criterion: Criterion,
    /// Seed quadrants 1 and 3 move along x when F = 0, 2 and 4 along y.
    seed_x_on_tie: bool,
    started: bool,
}

/// Moves needed to cover `delta` with moves of at most `step`.
fn moves(delta: f64, step: f64) -> Result<u32, Error> {
    let ratio = delta.abs() / step;
    if !ratio.is_finite() || ratio > f64::from(MAX_STEPS) {
        return Err(Error::TooManySteps);
    }
    // Tolerate rounding in |Δ|/step: 3.000000000001 steps are 3 moves.
    // In 0..=MAX_STEPS: the cast is exact.
    Ok(libm::ceil(ratio - 1e-9).max(0.0) as u32)
}

impl LineSteps {
    /// The line `start` → `end` with moves of at most `step_cm` (cm).
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`] (step ≤ 0),
    /// [`Error::TooManySteps`] (more than [`MAX_STEPS`] moves).
    pub fn new(
        start: BoardPoint,
        end: BoardPoint,
        step_cm: f64,
        criterion: Criterion,
    ) -> Result<Self, Error> {
        let step = check_step(step_cm)?;
        start.check_finite()?;
        end.check_finite()?;
        let (dx, dy) = (end.x_cm - start.x_cm, end.y_cm - start.y_cm);
        let nx = moves(dx, step)?;
        let ny = moves(dy, step)?;
        if nx.saturating_add(ny) > MAX_STEPS {
            return Err(Error::TooManySteps);
        }
        // Seed quadrant of (Xe, Ye) on the step lattice.
        let xe = if dx < 0.0 {
            -i64::from(nx)
        } else {
            i64::from(nx)
        };
        let ye = if dy < 0.0 {
            -i64::from(ny)
        } else {
            i64::from(ny)
        };
        let seed_x_on_tie = (xe > 0 && ye >= 0) || (xe < 0 && ye <= 0);
        Ok(Self {
            start,
            end,
            nx,
            ny,
            i: 0,
            j: 0,
            f: 0,
            criterion,
            seed_x_on_tie,
            started: false,
        })
    }

    /// Number of unit moves (points after the start point).
    pub fn moves(&self) -> u32 {
        self.nx + self.ny
    }

    fn move_x(&self) -> bool {
        if self.i >= self.nx {
            return false;
        }
        if self.j >= self.ny {
            return true;
        }
        match self.criterion {
            // Seed: F_seed = sx·sy·F; quadrants 1/3 step x when F_seed ≥ 0,
            // quadrants 2/4 when F_seed < 0: both are "F > 0, ties by
            // quadrant" in the mirrored frame.
            Criterion::Seed => self.f > 0 || (self.f == 0 && self.seed_x_on_tie),
            // F at the midpoint (i + ½, j + ½) is F + (nx − ny)/2.
            Criterion::Midpoint => 2 * self.f + i64::from(self.nx) - i64::from(self.ny) >= 0,
        }
    }

    fn coord(start: f64, end: f64, k: u32, n: u32) -> f64 {
        if k >= n {
            end
        } else {
            start + (end - start) * (f64::from(k) / f64::from(n))
        }
    }
}

impl Iterator for LineSteps {
    type Item = BoardPoint;

    fn next(&mut self) -> Option<BoardPoint> {
        if !self.started {
            self.started = true;
            return Some(self.start);
        }
        if self.i >= self.nx && self.j >= self.ny {
            return None;
        }
        if self.move_x() {
            self.i += 1;
            self.f -= i64::from(self.ny);
        } else {
            self.j += 1;
            self.f += i64::from(self.nx);
        }
        Some(BoardPoint {
            x_cm: Self::coord(self.start.x_cm, self.end.x_cm, self.i, self.nx),
            y_cm: Self::coord(self.start.y_cm, self.end.y_cm, self.j, self.ny),
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = (self.nx - self.i) + (self.ny - self.j) + u32::from(!self.started);
        let left = left as usize;
        (left, Some(left))
    }
}

impl ExactSizeIterator for LineSteps {}
impl FusedIterator for LineSteps {}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::path::test_support::cheb_to_segment;
    use proptest::prelude::*;
    use std::vec::Vec;

    fn pts(a: (f64, f64), b: (f64, f64), c: Criterion) -> Vec<(f64, f64)> {
        LineSteps::new(BoardPoint::new(a.0, a.1), BoardPoint::new(b.0, b.1), 1.0, c)
            .unwrap()
            .map(|p| (p.x_cm, p.y_cm))
            .collect()
    }

    /// The seed's `drawline` loop, transcribed literally (floats, Step_one = 1).
    fn seed_drawline(x0: f64, y0: f64, xe: f64, ye: f64) -> Vec<(f64, f64)> {
        let (xe, ye) = (xe - x0, ye - y0);
        let mut nxy = xe.abs() + ye.abs();
        let (mut fm, mut xm, mut ym) = (0.0, x0, y0);
        let xoy = if xe > 0.0 && ye >= 0.0 {
            1
        } else if xe <= 0.0 && ye > 0.0 {
            2
        } else if xe < 0.0 && ye <= 0.0 {
            3
        } else {
            4
        };
        let mut out = std::vec![(x0, y0)];
        while nxy > 0.0 {
            match xoy {
                1 => {
                    if fm >= 0.0 {
                        xm += 1.0
                    } else {
                        ym += 1.0
                    }
                }
                2 => {
                    if fm < 0.0 {
                        xm -= 1.0
                    } else {
                        ym += 1.0
                    }
                }
                3 => {
                    if fm >= 0.0 {
                        xm -= 1.0
                    } else {
                        ym -= 1.0
                    }
                }
                _ => {
                    if fm < 0.0 {
                        xm += 1.0
                    } else {
                        ym -= 1.0
                    }
                }
            }
            nxy -= 1.0;
            fm = (ym - y0) * xe - (xm - x0) * ye;
            out.push((xm, ym));
        }
        out
    }

    #[test]
    fn seed_criterion_reproduces_the_seed_code() {
        let ends = [
            (7.0, 3.0),
            (-7.0, 3.0),
            (-7.0, -3.0),
            (7.0, -3.0),
            (0.0, 5.0),
            (0.0, -5.0),
            (5.0, 0.0),
            (-5.0, 0.0),
            (4.0, 4.0),
            (-4.0, 4.0),
            (-4.0, -4.0),
            (4.0, -4.0),
            (10.0, 1.0),
            (1.0, -10.0),
        ];
        for (xe, ye) in ends {
            let from = (2.0, -1.0);
            let to = (2.0 + xe, -1.0 + ye);
            assert_eq!(
                pts(from, to, Criterion::Seed),
                seed_drawline(from.0, from.1, to.0, to.1),
                "to {to:?}"
            );
        }
    }

    #[test]
    fn seed_criterion_strays_up_to_a_step_midpoint_half() {
        // (0,0) → (10,1): the seed's second point (1,1) is 0.9 above the line.
        let s = pts((0.0, 0.0), (10.0, 1.0), Criterion::Seed);
        assert_eq!(s[2], (1.0, 1.0));
        let m = pts((0.0, 0.0), (10.0, 1.0), Criterion::Midpoint);
        assert_eq!(m[2], (2.0, 0.0));
        assert_eq!(m.last(), Some(&(10.0, 1.0)));
        // Midpoint takes the y move halfway: (1..=5, 0), then y, then x to 10.
        assert_eq!(m[5], (5.0, 0.0));
        assert_eq!(m[6], (5.0, 1.0));
        assert_eq!(m[7], (6.0, 1.0));
    }

    #[test]
    fn uneven_lengths_use_shorter_equal_moves_and_end_exactly() {
        let a = BoardPoint::new(0.1, 0.2);
        let b = BoardPoint::new(2.6, -1.33);
        let line = LineSteps::new(a, b, 1.0, Criterion::Midpoint).unwrap();
        // ⌈2.5⌉ + ⌈1.53⌉ = 3 + 2 moves.
        assert_eq!(line.moves(), 5);
        assert_eq!(line.len(), 6);
        let v: Vec<_> = line.collect();
        assert_eq!(v[0], a);
        assert_eq!(*v.last().unwrap(), b);
        for w in v.windows(2) {
            let (dx, dy) = ((w[1].x_cm - w[0].x_cm).abs(), (w[1].y_cm - w[0].y_cm).abs());
            assert!((dx == 0.0) != (dy == 0.0), "one axis per move");
            assert!(dx <= 1.0 && dy <= 1.0);
        }
    }

    #[test]
    fn degenerate_and_invalid_lines() {
        let p = BoardPoint::new(1.0, 1.0);
        let v: Vec<_> = LineSteps::new(p, p, 0.5, Criterion::Midpoint)
            .unwrap()
            .collect();
        assert_eq!(v, [p]);
        assert!(matches!(
            LineSteps::new(p, p, 0.0, Criterion::Midpoint),
            Err(Error::InvalidConfig { .. })
        ));
        assert_eq!(
            LineSteps::new(p, BoardPoint::new(f64::NAN, 0.0), 1.0, Criterion::Seed).err(),
            Some(Error::NonFinite { what: "x_cm" })
        );
        assert_eq!(
            LineSteps::new(p, BoardPoint::new(1e9, 0.0), 1e-3, Criterion::Seed).err(),
            Some(Error::TooManySteps)
        );
        assert_eq!(
            LineSteps::new(p, BoardPoint::new(1e308, 0.0), 1e-300, Criterion::Seed).err(),
            Some(Error::TooManySteps)
        );
    }

    fn check_line(
        a: BoardPoint,
        b: BoardPoint,
        step: f64,
        c: Criterion,
        bound: f64,
    ) -> Result<(), TestCaseError> {
        let v: Vec<_> = LineSteps::new(a, b, step, c).unwrap().collect();
        prop_assert_eq!(v[0], a);
        prop_assert_eq!(*v.last().unwrap(), b);
        for p in &v {
            let d = cheb_to_segment(*p, a, b);
            prop_assert!(
                d <= bound * step + 1e-9,
                "{:?} is {} steps off",
                p,
                d / step
            );
        }
        for w in v.windows(2) {
            let (dx, dy) = ((w[1].x_cm - w[0].x_cm).abs(), (w[1].y_cm - w[0].y_cm).abs());
            prop_assert!((dx == 0.0) != (dy == 0.0));
            prop_assert!(dx <= step * (1.0 + 1e-12) && dy <= step * (1.0 + 1e-12));
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1000))]

        #[test]
        fn midpoint_stays_within_half_a_step(
            x0 in -20.0f64..20.0, y0 in -20.0f64..20.0, x1 in -20.0f64..20.0, y1 in -20.0f64..20.0,
            step in 0.05f64..2.0,
        ) {
            check_line(BoardPoint::new(x0, y0), BoardPoint::new(x1, y1), step, Criterion::Midpoint, 0.5)?;
        }

        #[test]
        fn seed_stays_within_one_step(
            x0 in -20.0f64..20.0, y0 in -20.0f64..20.0, x1 in -20.0f64..20.0, y1 in -20.0f64..20.0,
            step in 0.05f64..2.0,
        ) {
            check_line(BoardPoint::new(x0, y0), BoardPoint::new(x1, y1), step, Criterion::Seed, 1.0)?;
        }
    }
}
