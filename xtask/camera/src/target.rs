//! The printed calibration target: AprilTag 36h11 markers at known board
//! coordinates around the working area, the grid points, and a scale bar.
//! One [`TargetLayout`] is both the SVG the user prints and what the
//! virtual camera renders.

use std::fmt::Write as _;

use kornia_apriltag::family::TagFamily;

/// Reflectance of the paper.
pub const PAPER: f64 = 1.0;
/// Reflectance of the printed ink.
pub const INK: f64 = 0.08;

/// The laser grid (SPEC §4.1): points at `(xi·pitch, yi·pitch)` mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridSpec {
    /// Grid pitch, mm.
    pub pitch_mm: f64,
    /// Grid indices run over `-xi_max..=xi_max`.
    pub xi_max: i32,
    /// Grid indices run over `-yi_max..=yi_max`.
    pub yi_max: i32,
}

impl Default for GridSpec {
    /// SPEC §4.1: pitch 1.916 cm, 12 × 8 cells.
    fn default() -> Self {
        Self {
            pitch_mm: 19.16,
            xi_max: 6,
            yi_max: 4,
        }
    }
}

/// One marker on the board.
#[derive(Debug, Clone, PartialEq)]
pub struct TagPlacement {
    /// AprilTag 36h11 id.
    pub id: u16,
    /// Centre, board mm.
    pub centre_mm: [f64; 2],
    /// Edge of the black border square, mm (the quiet zone adds 1/8 of it on each side).
    pub size_mm: f64,
    /// Cell colours, 10 × 10 (quiet zone included), row 0 at the top; `true` = ink.
    cells: [[bool; 10]; 10],
}

impl TagPlacement {
    /// Corners of the black border in tag order top-left, top-right,
    /// bottom-right, bottom-left (tag coordinates (±1, ±1), y down), board mm.
    pub fn corners_mm(&self) -> [[f64; 2]; 4] {
        let h = self.size_mm / 2.0;
        let [x, y] = self.centre_mm;
        [
            [x - h, y + h],
            [x + h, y + h],
            [x + h, y - h],
            [x - h, y - h],
        ]
    }

    /// Whether the tag's cell at `col`, `row` (0..10, quiet zone included) is ink.
    pub fn is_ink(&self, col: usize, row: usize) -> bool {
        self.cells
            .get(row)
            .and_then(|r| r.get(col))
            .copied()
            .unwrap_or(false)
    }

    /// Edge of one cell, mm.
    pub fn cell_mm(&self) -> f64 {
        self.size_mm / 8.0
    }
}

/// The cells of tag36h11 `id` (bits from the detector crate's family table).
fn tag_cells(family: &TagFamily, id: u16) -> Option<[[bool; 10]; 10]> {
    let code = *family.code_data.get(usize::from(id))?;
    let mut cells = [[false; 10]; 10];
    for (r, row) in cells.iter_mut().enumerate() {
        for (c, cell) in row.iter_mut().enumerate() {
            *cell = (1..=8).contains(&r) && (1..=8).contains(&c);
        }
    }
    for i in 0..family.nbits {
        let (bx, by) = (family.bit_x[i], family.bit_y[i]);
        let white = (code >> (family.nbits - 1 - i)) & 1 == 1;
        let (c, r) = (usize::try_from(bx + 1).ok()?, usize::try_from(by + 1).ok()?);
        *cells.get_mut(r)?.get_mut(c)? = !white;
    }
    Some(cells)
}

/// The whole printed board.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetLayout {
    /// The grid marked on the board.
    pub grid: GridSpec,
    /// The markers.
    pub tags: Vec<TagPlacement>,
    /// Scale bar: left end (board mm) and length (mm).
    pub scale_bar: ([f64; 2], f64),
    /// Printed area: `[x_min, y_min, x_max, y_max]`, board mm.
    pub extent_mm: [f64; 4],
}

/// Line width of the grid crosses, mm.
const CROSS_LINE_MM: f64 = 0.3;
/// Half length of a grid cross arm, mm.
const CROSS_ARM_MM: f64 = 2.0;
/// Thickness of the scale bar, mm.
const BAR_MM: f64 = 1.5;

impl TargetLayout {
    /// The layout for `grid`: the working area (grid + 10 mm) ringed by
    /// 14 tags (5 above, 5 below, 2 each side) sized to ~30 % of the
    /// working half-height, a 100 mm scale bar below.
    pub fn for_grid(grid: GridSpec) -> Result<Self, String> {
        if !(grid.pitch_mm.is_finite() && grid.pitch_mm > 0.0) || grid.xi_max < 1 || grid.yi_max < 1
        {
            return Err(format!("bad grid {grid:?}"));
        }
        let family = TagFamily::tag36_h11().map_err(|e| e.to_string())?;
        let wx = f64::from(grid.xi_max) * grid.pitch_mm + 10.0;
        let wy = f64::from(grid.yi_max) * grid.pitch_mm + 10.0;
        let size = (0.3 * wy).clamp(12.0, 40.0);
        let half_total = size * 10.0 / 16.0;
        let (xr, yr) = (wx + 4.0 + half_total, wy + 4.0 + half_total);
        let mut centres = Vec::new();
        for k in 0..5 {
            centres.push([-xr + f64::from(k) * xr / 2.0, yr]);
        }
        for k in 0..2 {
            let y = yr / 3.0 - f64::from(k) * 2.0 * yr / 3.0;
            centres.push([xr, y]);
        }
        for k in 0..5 {
            centres.push([xr - f64::from(k) * xr / 2.0, -yr]);
        }
        for k in 0..2 {
            let y = -yr / 3.0 + f64::from(k) * 2.0 * yr / 3.0;
            centres.push([-xr, y]);
        }
        let tags = centres
            .into_iter()
            .zip(0u16..)
            .map(|(centre_mm, id)| {
                let cells = tag_cells(&family, id).ok_or("tag36h11 table too short")?;
                Ok(TagPlacement {
                    id,
                    centre_mm,
                    size_mm: size,
                    cells,
                })
            })
            .collect::<Result<Vec<_>, String>>()?;
        let bar_y = -yr - half_total - 8.0;
        let margin = 6.0;
        Ok(Self {
            grid,
            tags,
            scale_bar: ([-50.0, bar_y], 100.0),
            extent_mm: [
                -xr - half_total - margin,
                bar_y - 12.0,
                xr + half_total + margin,
                yr + half_total + margin,
            ],
        })
    }

    /// The tag with `id`, if on this board.
    pub fn tag(&self, id: u16) -> Option<&TagPlacement> {
        self.tags.iter().find(|t| t.id == id)
    }

    /// Grid points, board mm, row by row from the top.
    pub fn grid_points_mm(&self) -> Vec<[f64; 2]> {
        let g = self.grid;
        (-g.yi_max..=g.yi_max)
            .rev()
            .flat_map(|yi| {
                (-g.xi_max..=g.xi_max)
                    .map(move |xi| [f64::from(xi) * g.pitch_mm, f64::from(yi) * g.pitch_mm])
            })
            .collect()
    }

    /// Printed reflectance at board point `p` (mm): [`INK`] or [`PAPER`].
    pub fn reflectance(&self, p: [f64; 2]) -> f64 {
        if self.ink_at(p) { INK } else { PAPER }
    }

    fn ink_at(&self, [x, y]: [f64; 2]) -> bool {
        for t in &self.tags {
            let cell = t.cell_mm();
            let col = (x - t.centre_mm[0]) / cell + 5.0;
            let row = (t.centre_mm[1] - y) / cell + 5.0;
            if (0.0..10.0).contains(&col) && (0.0..10.0).contains(&row) {
                return t.is_ink(col as usize, row as usize);
            }
        }
        let g = self.grid;
        let (gx, gy) = (x / g.pitch_mm, y / g.pitch_mm);
        let (nx, ny) = (gx.round(), gy.round());
        if nx.abs() <= f64::from(g.xi_max) && ny.abs() <= f64::from(g.yi_max) {
            let (dx, dy) = ((gx - nx) * g.pitch_mm, (gy - ny) * g.pitch_mm);
            let arm = |a: f64, b: f64| a.abs() <= CROSS_ARM_MM && b.abs() <= CROSS_LINE_MM / 2.0;
            if arm(dx, dy) || arm(dy, dx) {
                return true;
            }
        }
        let ([bx, by], len) = self.scale_bar;
        let on_bar =
            (bx..=bx + len).contains(&x) && (by - BAR_MM / 2.0..=by + BAR_MM / 2.0).contains(&y);
        let tick = ((x - bx) / 10.0).round();
        let on_tick = (0.0..=len / 10.0).contains(&tick)
            && ((x - bx) - tick * 10.0).abs() <= CROSS_LINE_MM / 2.0
            && (by..=by + 4.0).contains(&y);
        on_bar || on_tick
    }

    /// The printed ink as rectangles `[x, y, width, height]` (board mm,
    /// `x, y` the lower left corner): tag cells, grid crosses, the scale
    /// bar and its 10 mm ticks. Exactly where [`TargetLayout::reflectance`] is ink.
    pub fn ink_rects(&self) -> Vec<[f64; 4]> {
        let mut rects = Vec::new();
        for t in &self.tags {
            let cell = t.cell_mm();
            for row in 0..10 {
                for col in 0..10 {
                    if t.is_ink(col, row) {
                        let x = t.centre_mm[0] + (col as f64 - 5.0) * cell;
                        let top = t.centre_mm[1] - (row as f64 - 5.0) * cell;
                        rects.push([x, top - cell, cell, cell]);
                    }
                }
            }
        }
        let (a, l) = (CROSS_ARM_MM, CROSS_LINE_MM);
        for [x, y] in self.grid_points_mm() {
            rects.push([x - a, y - l / 2.0, 2.0 * a, l]);
            rects.push([x - l / 2.0, y - a, l, 2.0 * a]);
        }
        let ([bx, by], len) = self.scale_bar;
        rects.push([bx, by - BAR_MM / 2.0, len, BAR_MM]);
        for k in 0..=(len / 10.0) as u32 {
            let x = bx + f64::from(k) * 10.0 - CROSS_LINE_MM / 2.0;
            rects.push([x, by, CROSS_LINE_MM, 4.0]);
        }
        rects
    }

    /// The printed captions: `(x, y, size, text)`, baseline start in board
    /// mm, font size in mm.
    pub fn captions(&self) -> Vec<(f64, f64, f64, String)> {
        let ([bx, by], _) = self.scale_bar;
        let mut captions = vec![(
            bx,
            by - 6.0,
            3.5,
            "100 mm: check this bar after printing (print at 100 %, no scaling)".to_owned(),
        )];
        for t in &self.tags {
            captions.push((
                t.centre_mm[0] - t.size_mm / 2.0,
                t.centre_mm[1] - t.size_mm * 10.0 / 16.0 - 2.5,
                2.5,
                format!("tag36h11 #{}", t.id),
            ));
        }
        captions
    }

    /// The board as an SVG at true scale (1 user unit = 1 mm; print at 100 %).
    pub fn svg(&self) -> String {
        let [x0, y0, x1, y1] = self.extent_mm;
        let (w, h) = (x1 - x0, y1 - y0);
        let mut s = String::new();
        let _ = writeln!(
            s,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.3}mm\" height=\"{h:.3}mm\" \
             viewBox=\"{x0:.3} {:.3} {w:.3} {h:.3}\">",
            -y1
        );
        let _ = writeln!(
            s,
            "<rect x=\"{x0:.3}\" y=\"{:.3}\" width=\"{w:.3}\" height=\"{h:.3}\" fill=\"white\"/>",
            -y1
        );
        let _ = writeln!(s, "<g fill=\"black\" stroke=\"none\">");
        for [x, y, w, h] in self.ink_rects() {
            let _ = writeln!(
                s,
                "<rect x=\"{x:.4}\" y=\"{:.4}\" width=\"{w:.4}\" height=\"{h:.4}\"/>",
                -(y + h)
            );
        }
        let _ = writeln!(s, "</g>");
        let _ = writeln!(s, "<g font-family=\"sans-serif\" fill=\"#555\">");
        for (x, y, size, text) in self.captions() {
            let _ = writeln!(
                s,
                "<text x=\"{x:.3}\" y=\"{:.3}\" font-size=\"{size}\">{text}</text>",
                -y
            );
        }
        let _ = writeln!(s, "</g>\n</svg>");
        s
    }
}

#[cfg(test)]
mod tests;
