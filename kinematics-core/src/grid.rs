//! The test grid on the board (SPEC §4.1, §4.6): pitch, cells, offsets,
//! and grid index ↔ board point.
//!
//! A grid of `cols × rows` cells has `(cols + 1) × (rows + 1)` points with
//! indices `xi ∈ [−cols/2, cols/2]`, `yi ∈ [−rows/2, rows/2]`; index
//! `(xi, yi)` is the board point `(xi·pitch + x_offset, yi·pitch + y_offset)`
//! (the seed's `MoveToGrid`).

use crate::error::Error;
use crate::frames::BoardPoint;
use crate::numeric::{clamp, finite};

/// SPEC default grid pitch (measured; nominal 2 cm), cm.
pub const DEFAULT_PITCH_CM: f64 = 1.916;
/// SPEC default number of cells across.
pub const DEFAULT_COLS: u8 = 12;
/// SPEC default number of cells down.
pub const DEFAULT_ROWS: u8 = 8;

/// A grid point index: column `xi` (board x direction), row `yi` (board y).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct GridIndex {
    /// Column index, −cols/2..=cols/2.
    pub xi: i8,
    /// Row index, −rows/2..=rows/2.
    pub yi: i8,
}

impl GridIndex {
    /// Index `(xi, yi)`.
    pub const fn new(xi: i8, yi: i8) -> Self {
        Self { xi, yi }
    }
}

/// Grid geometry. `Copy`; [`Default`] is the SPEC grid (1.916 cm, 12 × 8
/// cells, no offsets).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Distance between neighbouring grid points, cm (> 0).
    pub pitch_cm: f64,
    /// Number of cells across (even).
    pub cols: u8,
    /// Number of cells down (even).
    pub rows: u8,
    /// Board x of grid index (0, 0), cm.
    pub x_offset_cm: f64,
    /// Board y of grid index (0, 0), cm.
    pub y_offset_cm: f64,
}

impl Default for Grid {
    fn default() -> Self {
        Self {
            pitch_cm: DEFAULT_PITCH_CM,
            cols: DEFAULT_COLS,
            rows: DEFAULT_ROWS,
            x_offset_cm: 0.0,
            y_offset_cm: 0.0,
        }
    }
}

impl Grid {
    /// Checks the pitch is finite and positive, offsets finite, and the
    /// cell counts even (so the grid is symmetric about index (0, 0)).
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`].
    pub fn validate(&self) -> Result<(), Error> {
        finite(self.pitch_cm, "pitch_cm")?;
        finite(self.x_offset_cm, "grid x_offset_cm")?;
        finite(self.y_offset_cm, "grid y_offset_cm")?;
        if self.pitch_cm <= 0.0 {
            return Err(Error::InvalidConfig {
                what: "grid pitch_cm must be > 0",
            });
        }
        if !self.cols.is_multiple_of(2) || !self.rows.is_multiple_of(2) {
            return Err(Error::InvalidConfig {
                what: "grid cols and rows must be even",
            });
        }
        Ok(())
    }

    /// Largest column index, `cols / 2`.
    pub fn max_xi(&self) -> i8 {
        half(self.cols)
    }

    /// Largest row index, `rows / 2`.
    pub fn max_yi(&self) -> i8 {
        half(self.rows)
    }

    /// Whether `idx` is a point of this grid.
    pub fn contains(&self, idx: GridIndex) -> bool {
        idx.xi.unsigned_abs() <= self.max_xi().unsigned_abs()
            && idx.yi.unsigned_abs() <= self.max_yi().unsigned_abs()
    }

    /// Board point (cm) of grid index `idx`.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`] (invalid
    /// grid), [`Error::GridIndexOutOfRange`].
    pub fn point(&self, idx: GridIndex) -> Result<BoardPoint, Error> {
        self.validate()?;
        if !self.contains(idx) {
            return Err(Error::GridIndexOutOfRange {
                xi: i16::from(idx.xi),
                yi: i16::from(idx.yi),
            });
        }
        Ok(self.point_of(idx))
    }

    /// Board point of `idx` without checks (callers validated).
    pub(crate) fn point_of(&self, idx: GridIndex) -> BoardPoint {
        BoardPoint {
            x_cm: f64::from(idx.xi) * self.pitch_cm + self.x_offset_cm,
            y_cm: f64::from(idx.yi) * self.pitch_cm + self.y_offset_cm,
        }
    }

    /// The grid index nearest to board point `p` (cm), clamped to the grid.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`].
    pub fn nearest_index(&self, p: BoardPoint) -> Result<GridIndex, Error> {
        self.validate()?;
        p.check_finite()?;
        let nearest = |v_cm: f64, off_cm: f64, max: i8| -> i8 {
            let m = f64::from(max);
            // Clamped to ±127, so the cast is exact.
            clamp(libm::round((v_cm - off_cm) / self.pitch_cm), -m, m) as i8
        };
        Ok(GridIndex {
            xi: nearest(p.x_cm, self.x_offset_cm, self.max_xi()),
            yi: nearest(p.y_cm, self.y_offset_cm, self.max_yi()),
        })
    }
}

fn half(cells: u8) -> i8 {
    // cells / 2 ≤ 127.
    (cells / 2) as i8
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn default_grid_matches_the_seed() {
        let g = Grid::default();
        assert_eq!((g.max_xi(), g.max_yi()), (6, 4));
        // Seed MoveToGrid(xi, yi) = MoveTo(xi·GRID_WIDTH, yi·GRID_WIDTH).
        let p = g.point(GridIndex::new(-6, 4)).unwrap();
        assert_eq!(p, BoardPoint::new(-6.0 * 1.916, 4.0 * 1.916));
        assert_eq!(g.indices().len(), 13 * 9);
    }

    #[test]
    fn offsets_shift_every_point() {
        let g = Grid {
            x_offset_cm: 0.5,
            y_offset_cm: -1.0,
            ..Grid::default()
        };
        assert_eq!(
            g.point(GridIndex::new(1, 1)).unwrap(),
            BoardPoint::new(1.916 + 0.5, 1.916 - 1.0)
        );
    }

    #[test]
    fn out_of_grid_and_invalid_grids_are_errors() {
        let g = Grid::default();
        assert_eq!(
            g.point(GridIndex::new(7, 0)),
            Err(Error::GridIndexOutOfRange { xi: 7, yi: 0 })
        );
        assert_eq!(
            g.point(GridIndex::new(0, -5)),
            Err(Error::GridIndexOutOfRange { xi: 0, yi: -5 })
        );
        assert!(g.point(GridIndex::new(i8::MIN, 0)).is_err());
        let odd = Grid {
            cols: 11,
            ..Grid::default()
        };
        assert!(matches!(
            odd.point(GridIndex::default()),
            Err(Error::InvalidConfig { .. })
        ));
        let flat = Grid {
            pitch_cm: 0.0,
            ..Grid::default()
        };
        assert!(matches!(flat.validate(), Err(Error::InvalidConfig { .. })));
        let nan = Grid {
            pitch_cm: f64::NAN,
            ..Grid::default()
        };
        assert_eq!(nan.validate(), Err(Error::NonFinite { what: "pitch_cm" }));
        assert!(g.nearest_index(BoardPoint::new(f64::NAN, 0.0)).is_err());
    }

    #[test]
    fn nearest_index_rounds_and_clamps() {
        let g = Grid::default();
        assert_eq!(
            g.nearest_index(BoardPoint::new(2.0, -0.9)).unwrap(),
            GridIndex::new(1, 0)
        );
        assert_eq!(
            g.nearest_index(BoardPoint::new(100.0, -100.0)).unwrap(),
            GridIndex::new(6, -4)
        );
    }

    #[test]
    fn largest_grid_fits_the_index_type() {
        let g = Grid {
            cols: 254,
            rows: 254,
            ..Grid::default()
        };
        assert_eq!(g.max_xi(), 127);
        assert_eq!(g.indices().len(), 255 * 255);
        assert!(g.point(GridIndex::new(-127, 127)).is_ok());
    }

    proptest! {
        #[test]
        fn nearest_index_inverts_point(
            xi in -6i8..=6, yi in -4i8..=4, pitch in 0.1f64..10.0, xo in -5.0f64..5.0, yo in -5.0f64..5.0,
        ) {
            let g = Grid { pitch_cm: pitch, x_offset_cm: xo, y_offset_cm: yo, ..Grid::default() };
            let idx = GridIndex::new(xi, yi);
            prop_assert_eq!(g.nearest_index(g.point(idx).unwrap()).unwrap(), idx);
        }
    }
}
