//! Grid indices of SPEC §4.6's patterns, written out from the spec (not
//! from the firmware's pattern code).

/// corner: (−6, 4) → (6, 4) → (6, −4) → (−6, −4).
pub fn corner() -> Vec<(i8, i8)> {
    vec![(-6, 4), (6, 4), (6, -4), (-6, -4)]
}
/// horizontal: xi = −6..6 at yi = 0.
pub fn horizontal() -> Vec<(i8, i8)> {
    (-6..=6).map(|x| (x, 0)).collect()
}
/// vertical: yi = 4..−4 at xi = 0.
pub fn vertical() -> Vec<(i8, i8)> {
    (-4..=4).rev().map(|y| (0, y)).collect()
}
/// visit-all: yi = 2..−2, xi = −3..3, row by row.
pub fn visit_all() -> Vec<(i8, i8)> {
    (-2..=2)
        .rev()
        .flat_map(|y| (-3..=3).map(move |x| (x, y)))
        .collect()
}
/// Full grid, raster: rows top to bottom, each left to right.
pub fn raster() -> Vec<(i8, i8)> {
    (-4..=4)
        .rev()
        .flat_map(|y| (-6..=6).map(move |x| (x, y)))
        .collect()
}
/// Full grid, serpentine: like raster with every second row reversed.
pub fn serpentine() -> Vec<(i8, i8)> {
    (-4..=4)
        .rev()
        .enumerate()
        .flat_map(|(row, y)| {
            let xs: Vec<i8> = if row % 2 == 0 {
                (-6..=6).collect()
            } else {
                (-6..=6).rev().collect()
            };
            xs.into_iter().map(move |x| (x, y))
        })
        .collect()
}
