//! The board figures of the product's own patterns, computed here from
//! SPEC §4.1, §4.3 and §4.6 and docs/console.md, independently of the
//! firmware's pattern, figure and sequencer code: grid points (board
//! `(xi·pitch + x_offset, yi·pitch + y_offset)`), the strokes of `line`,
//! `circle`, `rect` and `tuning`, and the pointing actuator's travel
//! between two points (straight in joint space, through the SPEC's exact
//! gimbal model), board mm.

use std::f64::consts::{FRAC_PI_2, TAU};

use super::gcode_piece::Piece;

/// Pieces one joint-space travel is drawn with.
const TRAVEL_PIECES: usize = 48;

/// The settings a figure depends on (the firmware's defaults until a
/// `set` changes them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct FigureSettings {
    /// `grid.pitch_cm`.
    pub(super) pitch_cm: f64,
    /// `grid.cols`.
    pub(super) cols: f64,
    /// `grid.rows`.
    pub(super) rows: f64,
    /// `grid.x_offset_cm`.
    pub(super) x_offset_cm: f64,
    /// `grid.y_offset_cm`.
    pub(super) y_offset_cm: f64,
    /// `oq_cm`: gimbal centre to board.
    pub(super) oq_cm: f64,
    /// `ol_cm`: laser axis offset.
    pub(super) ol_cm: f64,
    /// `path.step_cm`: the gimbal's interpolation step.
    pub(super) path_step_cm: f64,
}

impl Default for FigureSettings {
    /// SPEC §4.1 and docs/console.md: pitch 1.916 cm, 12 × 8 cells, no
    /// offsets, OQ 25 cm, OL 5.4 cm, path step 0.2 cm.
    fn default() -> Self {
        Self {
            pitch_cm: 1.916,
            cols: 12.0,
            rows: 8.0,
            x_offset_cm: 0.0,
            y_offset_cm: 0.0,
            oq_cm: 25.0,
            ol_cm: 5.4,
            path_step_cm: 0.2,
        }
    }
}

impl FigureSettings {
    /// Applies an accepted `set <name> <value>`; `false` when the name is
    /// not one a figure depends on.
    pub(super) fn set(&mut self, name: &str, value: f64) -> bool {
        let field = match name {
            "grid.pitch_cm" => &mut self.pitch_cm,
            "grid.cols" => &mut self.cols,
            "grid.rows" => &mut self.rows,
            "grid.x_offset_cm" => &mut self.x_offset_cm,
            "grid.y_offset_cm" => &mut self.y_offset_cm,
            "oq_cm" => &mut self.oq_cm,
            "ol_cm" => &mut self.ol_cm,
            "path.step_cm" => &mut self.path_step_cm,
            _ => return false,
        };
        *field = value;
        true
    }

    /// Grid point `(xi, yi)` on the board, mm.
    pub(super) fn grid_mm(&self, xi: i32, yi: i32) -> [f64; 2] {
        [
            10.0 * (f64::from(xi) * self.pitch_cm + self.x_offset_cm),
            10.0 * (f64::from(yi) * self.pitch_cm + self.y_offset_cm),
        ]
    }

    /// Largest |xi| and |yi| of the grid (`cols / 2`, `rows / 2`).
    fn max_index(&self) -> (i32, i32) {
        (
            (self.cols / 2.0).floor() as i32,
            (self.rows / 2.0).floor() as i32,
        )
    }
}

/// What a `pattern`, `goto` or `grid` line draws, board mm.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Drawing {
    /// Points held in this order (lit at each, in every lit mode).
    Points(Vec<[f64; 2]>),
    /// Strokes, each drawn without a break, in this order.
    Strokes(Vec<Vec<Piece>>),
}

/// The figure of the arguments of an accepted `pattern` line (`None`:
/// not understood, then it is not judged).
pub(super) fn pattern(args: &[&str], s: &FigureSettings) -> Option<Drawing> {
    let args: Vec<&str> = args.iter().copied().filter(|a| *a != "once").collect();
    let (mx, my) = s.max_index();
    let grid = |ids: Vec<(i32, i32)>| {
        Some(Drawing::Points(
            ids.into_iter().map(|(x, y)| s.grid_mm(x, y)).collect(),
        ))
    };
    let nums: Option<Vec<f64>> = args
        .iter()
        .skip(1)
        .filter(|a| !matches!(**a, "cw" | "ccw" | "raster" | "serpentine"))
        .map(|a| a.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect();
    let mm = |v: f64| v * 10.0;
    match (*args.first()?, nums?.as_slice()) {
        ("home", []) => grid(vec![(0, 0)]),
        ("corner", []) => grid(vec![(-mx, my), (mx, my), (mx, -my), (-mx, -my)]),
        ("horizontal", []) => grid((-mx..=mx).map(|x| (x, 0)).collect()),
        ("vertical", []) => grid((-my..=my).rev().map(|y| (0, y)).collect()),
        ("visit-all", []) => grid(rows(mx.min(3), my.min(2), false)),
        ("grid-full", []) => grid(rows(mx, my, args.get(1) == Some(&"serpentine"))),
        ("line", &[x0, y0, x1, y1]) => Some(Drawing::Strokes(vec![vec![Piece::Line {
            a: [mm(x0), mm(y0)],
            b: [mm(x1), mm(y1)],
        }]])),
        ("circle", &[cx, cy, r]) => Some(Drawing::Strokes(vec![vec![circle(
            [mm(cx), mm(cy)],
            mm(r),
        )]])),
        ("rect", &[x0, y0, x1, y1]) => Some(Drawing::Strokes(vec![rect(
            [mm(x0), mm(y0)],
            [mm(x1), mm(y1)],
        )])),
        ("tuning", []) => Some(tuning([0.0, 0.0], 40.0)),
        ("tuning", &[cx, cy, size]) => Some(tuning([mm(cx), mm(cy)], mm(size))),
        _ => None,
    }
}

/// Every grid row from the top, each left to right (`serpentine`: every
/// second one right to left).
fn rows(mx: i32, my: i32, serpentine: bool) -> Vec<(i32, i32)> {
    let mut out = Vec::new();
    for (k, y) in (-my..=my).rev().enumerate() {
        let mut row: Vec<(i32, i32)> = (-mx..=mx).map(|x| (x, y)).collect();
        if serpentine && k % 2 == 1 {
            row.reverse();
        }
        out.extend(row);
    }
    out
}

/// A full circle (its direction does not change the figure).
fn circle(centre: [f64; 2], radius: f64) -> Piece {
    Piece::Arc {
        centre,
        radius: radius.abs(),
        start_rad: 0.0,
        sweep_rad: TAU,
    }
}

/// The border of the rectangle through opposite corners `a`, `b`.
fn rect(a: [f64; 2], b: [f64; 2]) -> Vec<Piece> {
    let c = [[a[0], a[1]], [b[0], a[1]], [b[0], b[1]], [a[0], b[1]]];
    (0..4)
        .map(|k| Piece::Line {
            a: c[k],
            b: c[(k + 1) % 4],
        })
        .collect()
}

/// The tuning figure: square of side `size`, its inscribed circle and the
/// cross through the centre, four strokes.
fn tuning(c: [f64; 2], size: f64) -> Drawing {
    let h = size / 2.0;
    let line = |a: [f64; 2], b: [f64; 2]| vec![Piece::Line { a, b }];
    Drawing::Strokes(vec![
        rect([c[0] - h, c[1] + h], [c[0] + h, c[1] - h]),
        vec![circle(c, h)],
        line([c[0] - h, c[1]], [c[0] + h, c[1]]),
        line([c[0], c[1] + h], [c[0], c[1] - h]),
    ])
}

/// Joint angles (yaw α, pitch β, rad) aiming at board point `p` (mm),
/// SPEC §4.3's exact IK with the laser axis `ol_cm` off the centre.
fn ik(p: [f64; 2], oq_cm: f64, ol_cm: f64) -> Option<[f64; 2]> {
    let (xg, yg, zg) = (oq_cm, -p[0] / 10.0, p[1] / 10.0);
    let h = xg.hypot(yg);
    let r = h.hypot(zg);
    if r <= ol_cm || xg <= 0.0 {
        return None;
    }
    let beta = FRAC_PI_2 - (zg.atan2(h) + (ol_cm / r).acos());
    Some([yg.atan2(xg), beta]).filter(|a| a.iter().all(|v| v.is_finite()))
}

/// Where joint angles `j` put the spot on the board, mm (SPEC §4.3's
/// exact FK).
fn fk(j: [f64; 2], oq_cm: f64, ol_cm: f64) -> Option<[f64; 2]> {
    let (sa, ca) = j[0].sin_cos();
    let (sb, cb) = j[1].sin_cos();
    let origin = [ol_cm * sb * ca, ol_cm * sb * sa, ol_cm * cb];
    let dir = [cb * ca, cb * sa, -sb];
    if dir[0] <= 1e-9 {
        return None;
    }
    let t = (oq_cm - origin[0]) / dir[0];
    let spot = [origin[1] + t * dir[1], origin[2] + t * dir[2]];
    Some([-spot[0] * 10.0, spot[1] * 10.0]).filter(|p| p.iter().all(|v| v.is_finite()))
}

/// The spot's path from `a` to `b` (mm) when the actuator moves straight
/// in joint space, as lines; `ol_cm` 0 for the stepper pan/tilt (its axes
/// meet at the beam). Empty when either end cannot be aimed at.
pub(super) fn travel(a: [f64; 2], b: [f64; 2], s: &FigureSettings, ol_cm: f64) -> Vec<Piece> {
    let (Some(ja), Some(jb)) = (ik(a, s.oq_cm, ol_cm), ik(b, s.oq_cm, ol_cm)) else {
        return Vec::new();
    };
    let at = |f: f64| {
        fk(
            [ja[0] + f * (jb[0] - ja[0]), ja[1] + f * (jb[1] - ja[1])],
            s.oq_cm,
            ol_cm,
        )
    };
    let points: Option<Vec<[f64; 2]>> = (0..=TRAVEL_PIECES)
        .map(|k| at(k as f64 / TRAVEL_PIECES as f64))
        .collect();
    points.map_or_else(Vec::new, |p| {
        p.windows(2)
            .map(|w| Piece::Line { a: w[0], b: w[1] })
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fk_inverts_ik_and_the_spec_grid_corner_is_where_it_should_be() {
        let s = FigureSettings::default();
        let corner = s.grid_mm(6, -4);
        assert!((corner[0] - 114.96).abs() < 1e-9 && (corner[1] + 76.64).abs() < 1e-9);
        for ol in [0.0, 5.4] {
            let j = ik(corner, 25.0, ol).unwrap();
            let back = fk(j, 25.0, ol).unwrap();
            assert!((back[0] - corner[0]).abs() < 1e-9 && (back[1] - corner[1]).abs() < 1e-9);
        }
        // The board's centre: yaw 0, and the beam hits it.
        let j = ik([0.0, 0.0], 25.0, 5.4).unwrap();
        assert!(j[0].abs() < 1e-12);
    }

    #[test]
    fn a_joint_space_travel_bows_off_the_chord_between_far_points() {
        let s = FigureSettings::default();
        let (a, b) = (s.grid_mm(-6, 4), s.grid_mm(6, 4));
        let path = travel(a, b, &s, s.ol_cm);
        assert_eq!(path.len(), TRAVEL_PIECES);
        let chord = Piece::Line { a, b };
        let bow = path
            .iter()
            .map(|p| chord.distance_mm(p.end()))
            .fold(0.0, f64::max);
        assert!(bow > 2.0, "the travel is not the chord: {bow} mm");
        assert!(path[0].distance_mm(a) < 1e-9);
        assert!(path[TRAVEL_PIECES - 1].distance_mm(b) < 1e-9);
    }

    #[test]
    fn patterns_are_the_spec_figures() {
        let s = FigureSettings::default();
        let Some(Drawing::Points(p)) = pattern(&["grid-full", "serpentine", "once"], &s) else {
            panic!("grid-full is points");
        };
        assert_eq!(p.len(), 13 * 9);
        assert_eq!((p[0], p[13]), (s.grid_mm(-6, 4), s.grid_mm(6, 3)));
        let Some(Drawing::Points(p)) = pattern(&["visit-all"], &s) else {
            panic!("visit-all is points");
        };
        assert_eq!((p.len(), p[0]), (35, s.grid_mm(-3, 2)));
        let Some(Drawing::Strokes(t)) = pattern(&["tuning"], &s) else {
            panic!("tuning is strokes");
        };
        assert_eq!(t.len(), 4);
        assert!((t[1][0].distance_mm([0.0, 20.0])).abs() < 1e-9);
        assert_eq!(pattern(&["circle", "1", "2"], &s), None);
        assert_eq!(pattern(&["line", "1", "2", "x", "4"], &s), None);
        assert!(pattern(&["circle", "1", "2", "3", "cw", "once"], &s).is_some());
    }
}
