extern crate std;
use super::*;
use std::collections::HashSet;
use std::vec::Vec;

fn ids(p: Pattern, g: &Grid) -> Vec<(i8, i8)> {
    p.indices(g).map(|i| (i.xi, i.yi)).collect()
}

#[test]
fn seed_patterns_in_seed_order() {
    let g = Grid::default();
    assert_eq!(ids(Pattern::Home, &g), [(0, 0)]);
    // TestCorner: A(−6, 4), B(6, 4), C(6, −4), D(−6, −4).
    assert_eq!(
        ids(Pattern::Corner, &g),
        [(-6, 4), (6, 4), (6, -4), (-6, -4)]
    );
    // TestHorizontal: for (xi = −6; xi <= 6; xi++) MoveToGrid(xi, 0).
    let mut expect = Vec::new();
    for xi in -6..=6 {
        expect.push((xi, 0));
    }
    assert_eq!(ids(Pattern::Horizontal, &g), expect);
    // TestVertical: for (yi = 4; yi >= −4; yi--) MoveToGrid(0, yi).
    let mut expect = Vec::new();
    for yi in (-4..=4).rev() {
        expect.push((0, yi));
    }
    assert_eq!(ids(Pattern::Vertical, &g), expect);
    // TestVisitAllGrid: for yi = 2..=−2 { for xi = −3..=3 }.
    let mut expect = Vec::new();
    for yi in (-2..=2).rev() {
        for xi in -3..=3 {
            expect.push((xi, yi));
        }
    }
    assert_eq!(ids(Pattern::VisitAll, &g), expect);
    assert_eq!(expect.len(), 35);
}

#[test]
fn full_raster_is_the_seed_loop_over_the_whole_grid() {
    let g = Grid::default();
    let mut expect = Vec::new();
    for yi in (-4..=4).rev() {
        for xi in -6..=6 {
            expect.push((xi, yi));
        }
    }
    assert_eq!(ids(Pattern::FullRaster, &g), expect);
}

#[test]
fn serpentine_covers_the_grid_with_unit_moves() {
    for (cols, rows) in [(12, 8), (2, 2), (0, 4), (6, 0), (20, 14)] {
        let g = Grid {
            cols,
            rows,
            ..Grid::default()
        };
        let s = ids(Pattern::FullSerpentine, &g);
        let all: HashSet<_> = ids(Pattern::FullRaster, &g).into_iter().collect();
        assert_eq!(s.len(), all.len());
        assert_eq!(s.iter().copied().collect::<HashSet<_>>(), all);
        assert_eq!(s[0], (-(cols as i8 / 2), rows as i8 / 2));
        for w in s.windows(2) {
            let d = (w[1].0 - w[0].0).abs() + (w[1].1 - w[0].1).abs();
            assert_eq!(d, 1, "{:?} → {:?}", w[0], w[1]);
        }
    }
}

#[test]
fn visit_all_is_clipped_to_small_grids() {
    let g = Grid {
        cols: 4,
        rows: 2,
        ..Grid::default()
    };
    let v = ids(Pattern::VisitAll, &g);
    assert_eq!(v.len(), 5 * 3);
    assert!(v.iter().all(|&(x, y)| x.abs() <= 2 && y.abs() <= 1));
}

#[test]
fn every_index_is_in_the_grid_and_lengths_are_exact() {
    for (cols, rows) in [(12, 8), (2, 2), (40, 40), (254, 2), (0, 0)] {
        let g = Grid {
            cols,
            rows,
            ..Grid::default()
        };
        for p in Pattern::ALL {
            let it = p.indices(&g);
            let n = it.len();
            let v: Vec<_> = it.collect();
            assert_eq!(v.len(), n, "{p:?}");
            assert!(v.iter().all(|&i| g.contains(i)), "{p:?}");
            let mut rev: Vec<_> = p.indices(&g).rev().collect();
            rev.reverse();
            assert_eq!(rev, v, "{p:?}");
        }
    }
}

#[test]
fn nth_jumps_to_the_same_index_as_walking() {
    for (cols, rows) in [(12, 8), (2, 2), (254, 254), (0, 0)] {
        let g = Grid {
            cols,
            rows,
            ..Grid::default()
        };
        for p in Pattern::ALL {
            let all: Vec<_> = p.indices(&g).collect();
            for k in [0, 1, all.len() / 2, all.len().saturating_sub(1), all.len()] {
                let mut it = p.indices(&g);
                assert_eq!(it.nth(k), all.get(k).copied(), "{p:?} {k}");
                // The iterator goes on after the index it jumped to.
                assert_eq!(it.next(), all.get(k + 1).copied(), "{p:?} {k}");
            }
            let mut it = p.indices(&g);
            assert_eq!(it.nth(usize::MAX), None);
            assert_eq!(it.next(), None);
        }
    }
}

#[test]
fn points_are_the_grid_points() {
    let g = Grid {
        pitch_cm: 2.0,
        x_offset_cm: 1.0,
        ..Grid::default()
    };
    let pts: Vec<_> = Pattern::Corner.points(&g).unwrap().collect();
    assert_eq!(
        pts,
        [
            BoardPoint::new(-11.0, 8.0),
            BoardPoint::new(13.0, 8.0),
            BoardPoint::new(13.0, -8.0),
            BoardPoint::new(-11.0, -8.0)
        ]
    );
    let pairs: Vec<_> = Pattern::Home.points(&g).unwrap().with_indices().collect();
    assert_eq!(pairs, [(GridIndex::new(0, 0), BoardPoint::new(1.0, 0.0))]);
    let bad = Grid {
        pitch_cm: -1.0,
        ..Grid::default()
    };
    assert!(Pattern::Home.points(&bad).is_err());
}

#[test]
fn names_round_trip() {
    for p in Pattern::ALL {
        assert_eq!(Pattern::from_name(p.name()), Some(p));
    }
    assert_eq!(Pattern::from_name("Visit-All"), Some(Pattern::VisitAll));
    assert_eq!(Pattern::from_name("spiral"), None);
}
