//! Named grid test patterns (SPEC §4.6, the seed's `Test…` functions) as
//! allocation-free iterators of grid indices and of board points.
//!
//! With the default 12 × 8 grid (`X = 6`, `Y = 4` below; other grids scale):
//!
//! | pattern | order |
//! |---|---|
//! | home | (0, 0) |
//! | corner | (−X, Y) → (X, Y) → (X, −Y) → (−X, −Y) |
//! | horizontal | xi = −X..X at yi = 0 |
//! | vertical | yi = Y..−Y at xi = 0 |
//! | visit-all | the seed's subset: yi = 2..−2, each row xi = −3..3 (clipped to the grid) |
//! | full raster | yi = Y..−Y, each row xi = −X..X |
//! | full serpentine | yi = Y..−Y, rows alternately left→right and right→left |

use core::iter::FusedIterator;

use crate::error::Error;
use crate::frames::BoardPoint;
use crate::grid::{Grid, GridIndex};

/// Half-width (columns) of the seed's visit-all subset.
const VISIT_ALL_MAX_XI: i8 = 3;
/// Half-height (rows) of the seed's visit-all subset.
const VISIT_ALL_MAX_YI: i8 = 2;

/// A named grid pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Pattern {
    /// Grid (0, 0) only.
    Home,
    /// The four corners, clockwise from top left.
    Corner,
    /// The middle row, left to right.
    Horizontal,
    /// The middle column, top to bottom.
    Vertical,
    /// The seed's `TestVisitAllGrid` subset (5 rows × 7 columns), raster.
    VisitAll,
    /// Every grid point, raster (each row left to right, rows top down).
    FullRaster,
    /// Every grid point, serpentine (alternate row directions, rows top down).
    FullSerpentine,
}

impl Pattern {
    /// Every pattern, in the order above.
    pub const ALL: [Pattern; 7] = [
        Pattern::Home,
        Pattern::Corner,
        Pattern::Horizontal,
        Pattern::Vertical,
        Pattern::VisitAll,
        Pattern::FullRaster,
        Pattern::FullSerpentine,
    ];

    /// Command-line name: `home`, `corner`, `horizontal`, `vertical`,
    /// `visit-all`, `grid-full-raster`, `grid-full-serpentine`.
    pub fn name(self) -> &'static str {
        match self {
            Pattern::Home => "home",
            Pattern::Corner => "corner",
            Pattern::Horizontal => "horizontal",
            Pattern::Vertical => "vertical",
            Pattern::VisitAll => "visit-all",
            Pattern::FullRaster => "grid-full-raster",
            Pattern::FullSerpentine => "grid-full-serpentine",
        }
    }

    /// The pattern called `name` (ASCII case-insensitive).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name))
    }

    /// The pattern's grid indices on `grid`. Never fails: only the cell
    /// counts are used; an odd count behaves as the next lower even one.
    pub fn indices(self, grid: &Grid) -> PatternIndices {
        let (max_xi, max_yi) = (grid.max_xi(), grid.max_yi());
        let (block_xi, block_yi) = match self {
            Pattern::VisitAll => (max_xi.min(VISIT_ALL_MAX_XI), max_yi.min(VISIT_ALL_MAX_YI)),
            _ => (max_xi, max_yi),
        };
        let mut it = PatternIndices {
            pattern: self,
            max_xi: i16::from(max_xi),
            max_yi: i16::from(max_yi),
            block_xi: i16::from(block_xi),
            block_yi: i16::from(block_yi),
            front: 0,
            back: 0,
        };
        it.back = it.total();
        it
    }

    /// The pattern's board points (cm) on `grid`.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`] (invalid grid).
    pub fn points(self, grid: &Grid) -> Result<PatternPoints, Error> {
        grid.validate()?;
        Ok(PatternPoints {
            indices: self.indices(grid),
            grid: *grid,
        })
    }
}

// The grid's own enumeration lives here, above both: the grid does not
// know the patterns.
impl Grid {
    /// Every grid index, row by row from the top (`yi = rows/2` down), each
    /// row left to right: the [`Pattern::FullRaster`] order.
    pub fn indices(&self) -> PatternIndices {
        Pattern::FullRaster.indices(self)
    }
}

/// Iterator over a pattern's grid indices (see [`Pattern::indices`]).
/// Exact size, double-ended, no allocation.
#[derive(Debug, Clone)]
pub struct PatternIndices {
    pattern: Pattern,
    max_xi: i16,
    max_yi: i16,
    block_xi: i16,
    block_yi: i16,
    front: u16,
    back: u16,
}

impl PatternIndices {
    /// Total number of indices of the pattern (≤ 255²).
    fn total(&self) -> u16 {
        let span = |h: i16| (2 * h + 1).unsigned_abs();
        match self.pattern {
            Pattern::Home => 1,
            Pattern::Corner => 4,
            Pattern::Horizontal => span(self.max_xi),
            Pattern::Vertical => span(self.max_yi),
            Pattern::VisitAll | Pattern::FullRaster | Pattern::FullSerpentine => {
                span(self.block_xi).saturating_mul(span(self.block_yi))
            }
        }
    }

    /// The `k`-th index of the pattern (`k < total`).
    fn at(&self, k: u16) -> GridIndex {
        let k = i32::from(k);
        let (x, y) = (i32::from(self.max_xi), i32::from(self.max_yi));
        let (xi, yi) = match self.pattern {
            Pattern::Home => (0, 0),
            Pattern::Corner => match k {
                0 => (-x, y),
                1 => (x, y),
                2 => (x, -y),
                _ => (-x, -y),
            },
            Pattern::Horizontal => (-x + k, 0),
            Pattern::Vertical => (0, y - k),
            Pattern::VisitAll | Pattern::FullRaster | Pattern::FullSerpentine => {
                let (bx, by) = (i32::from(self.block_xi), i32::from(self.block_yi));
                let width = 2 * bx + 1;
                let row = k.checked_div(width).unwrap_or(0);
                let col = k.checked_rem(width).unwrap_or(0);
                let xi = if self.pattern == Pattern::FullSerpentine && row % 2 == 1 {
                    bx - col
                } else {
                    -bx + col
                };
                (xi, by - row)
            }
        };
        // |xi| ≤ 127, |yi| ≤ 127 by construction.
        GridIndex::new(xi as i8, yi as i8)
    }
}

impl Iterator for PatternIndices {
    type Item = GridIndex;

    fn next(&mut self) -> Option<GridIndex> {
        if self.front >= self.back {
            return None;
        }
        let idx = self.at(self.front);
        self.front += 1;
        Some(idx)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = usize::from(self.back.saturating_sub(self.front));
        (n, Some(n))
    }

    /// The `n`-th next index in O(1) (indices are computed, not walked).
    fn nth(&mut self, n: usize) -> Option<GridIndex> {
        let left = usize::from(self.back.saturating_sub(self.front));
        if n >= left {
            self.front = self.back;
            return None;
        }
        // n < left ≤ u16::MAX.
        self.front += n as u16;
        self.next()
    }
}

impl DoubleEndedIterator for PatternIndices {
    fn next_back(&mut self) -> Option<GridIndex> {
        if self.front >= self.back {
            return None;
        }
        self.back -= 1;
        Some(self.at(self.back))
    }
}

impl ExactSizeIterator for PatternIndices {}
impl FusedIterator for PatternIndices {}

/// Iterator over a pattern's board points (cm), see [`Pattern::points`].
#[derive(Debug, Clone)]
pub struct PatternPoints {
    indices: PatternIndices,
    grid: Grid,
}

impl PatternPoints {
    /// The grid index of each point alongside it.
    pub fn with_indices(self) -> impl Iterator<Item = (GridIndex, BoardPoint)> {
        let grid = self.grid;
        self.indices.map(move |i| (i, grid.point_of(i)))
    }
}

impl Iterator for PatternPoints {
    type Item = BoardPoint;

    fn next(&mut self) -> Option<BoardPoint> {
        self.indices.next().map(|i| self.grid.point_of(i))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.indices.size_hint()
    }
}

impl DoubleEndedIterator for PatternPoints {
    fn next_back(&mut self) -> Option<BoardPoint> {
        self.indices.next_back().map(|i| self.grid.point_of(i))
    }
}

impl ExactSizeIterator for PatternPoints {}
impl FusedIterator for PatternPoints {}

#[cfg(test)]
mod tests;
