//! A realistic laser job and its toolpath, built from the same shapes but
//! independently of the firmware's G-code parser: the G-code text in the
//! form laser CAM tools (LaserGRBL, LightBurn's grbl output) emit — header
//! `G00 G17 G40 G21 G54`, `G90`, `M4`, `G0` travel, `G1`/`G2`/`G3` with `F`
//! and `S`, `M5`, `M2` — and the lit path it must draw, to compare with
//! what the simulator recorded.

use std::f64::consts::TAU;
use std::fmt::Write;

/// A piece of the lit toolpath, mm.
#[derive(Debug, Clone, Copy)]
pub enum Piece {
    /// Straight from `a` to `b`.
    Line { a: [f64; 2], b: [f64; 2] },
    /// Full circle.
    Circle { centre: [f64; 2], radius: f64 },
}

impl Piece {
    /// Distance from `p` to this piece, mm.
    pub fn distance(&self, p: [f64; 2]) -> f64 {
        match *self {
            Piece::Line { a, b } => {
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let len2 = dx * dx + dy * dy;
                let t = if len2 == 0.0 {
                    0.0
                } else {
                    (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
                };
                (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
            }
            Piece::Circle { centre, radius } => {
                ((p[0] - centre[0]).hypot(p[1] - centre[1]) - radius).abs()
            }
        }
    }

    /// Points along the piece every `step` mm or closer.
    pub fn points(&self, step: f64) -> Vec<[f64; 2]> {
        match *self {
            Piece::Line { a, b } => {
                let n = ((a[0] - b[0]).hypot(a[1] - b[1]) / step).ceil().max(1.0) as usize;
                (0..=n)
                    .map(|k| {
                        let t = k as f64 / n as f64;
                        [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
                    })
                    .collect()
            }
            Piece::Circle { centre, radius } => {
                let n = (TAU * radius / step).ceil().max(8.0) as usize;
                (0..n)
                    .map(|k| {
                        let a = TAU * k as f64 / n as f64;
                        [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()]
                    })
                    .collect()
            }
        }
    }
}

/// A job: its G-code lines and the lit toolpath.
#[derive(Debug, Clone, Default)]
pub struct Job {
    /// G-code lines, in order.
    pub lines: Vec<String>,
    /// What must be drawn lit.
    pub pieces: Vec<Piece>,
    /// Each G0 as (from, to), mm: the laser must be dark on the way.
    pub rapids: Vec<Rapid>,
    /// Where the last motion line ends, mm (`None` before the first).
    pub(crate) at: Option<[f64; 2]>,
}

/// A G0 move on the board, mm.
#[derive(Debug, Clone, Copy)]
pub struct Rapid {
    /// Where the spot is when the G0 starts (`None`: wherever it was
    /// before the job).
    pub from: Option<[f64; 2]>,
    /// The G0's target.
    pub to: [f64; 2],
}

fn num(v: f64) -> String {
    let mut s = format!("{v:.3}");
    while s.ends_with('0') {
        s.pop();
    }
    if s.ends_with('.') {
        s.pop();
    }
    if s == "-0" { "0".into() } else { s }
}

impl Job {
    /// Appends a line as it is.
    pub fn line(&mut self, text: impl Into<String>) {
        self.lines.push(text.into());
    }

    /// A G0 to `p`, mm.
    pub fn rapid(&mut self, p: [f64; 2]) {
        self.line(format!("G0 X{} Y{}", num(p[0]), num(p[1])));
        self.record_rapid(p);
    }

    /// Records a G0 to `p` (the line is already in `lines`).
    pub(crate) fn record_rapid(&mut self, p: [f64; 2]) {
        self.rapids.push(Rapid {
            from: self.at,
            to: p,
        });
        self.at = Some(p);
    }

    /// A lit polyline (first point reached by G0).
    pub fn polyline(&mut self, points: &[[f64; 2]], feed: f64, power: f64) {
        self.rapid(points[0]);
        for (k, w) in points.windows(2).enumerate() {
            let f = if k == 0 {
                format!(" F{} S{}", num(feed), num(power))
            } else {
                String::new()
            };
            self.line(format!("G1 X{} Y{}{f}", num(w[1][0]), num(w[1][1])));
            self.pieces.push(Piece::Line { a: w[0], b: w[1] });
            self.at = Some(w[1]);
        }
    }

    /// A full circle from its rightmost point, as two half arcs (`G2`
    /// with I/J) or one R-less full circle (`G3` with I/J to the start).
    fn circle(&mut self, centre: [f64; 2], radius: f64, feed: f64, power: f64, halves: bool) {
        let start = [centre[0] + radius, centre[1]];
        self.rapid(start);
        if halves {
            let left = [centre[0] - radius, centre[1]];
            self.line(format!(
                "G2 X{} Y{} I{} J0 F{} S{}",
                num(left[0]),
                num(left[1]),
                num(-radius),
                num(feed),
                num(power)
            ));
            self.line(format!(
                "G2 X{} Y{} I{} J0",
                num(start[0]),
                num(start[1]),
                num(radius)
            ));
        } else {
            self.line(format!(
                "G3 X{} Y{} I{} J0 F{} S{}",
                num(start[0]),
                num(start[1]),
                num(-radius),
                num(feed),
                num(power)
            ));
        }
        self.pieces.push(Piece::Circle { centre, radius });
    }

    /// Number of motion lines (G0/G1/G2/G3).
    pub fn motion_lines(&self) -> usize {
        self.lines
            .iter()
            .filter(|l| l.starts_with('G') && !l.starts_with("G00 G17"))
            .count()
    }

    /// The G-code as a file (`\n` line ends).
    pub fn text(&self) -> String {
        let mut out = String::new();
        for l in &self.lines {
            let _ = writeln!(out, "{l}");
        }
        out
    }
}

/// The outline of the letters "LA" (polylines), `h` mm tall, lower left at
/// `at`.
fn letters(at: [f64; 2], h: f64) -> Vec<Vec<[f64; 2]>> {
    let p = |x: f64, y: f64| [at[0] + x * h, at[1] + y * h];
    vec![
        // L, outline.
        vec![
            p(0.0, 0.0),
            p(0.0, 1.0),
            p(0.15, 1.0),
            p(0.15, 0.15),
            p(0.6, 0.15),
            p(0.6, 0.0),
            p(0.0, 0.0),
        ],
        // A, outer outline.
        vec![
            p(0.8, 0.0),
            p(1.1, 1.0),
            p(1.3, 1.0),
            p(1.6, 0.0),
            p(1.45, 0.0),
            p(1.37, 0.3),
            p(1.03, 0.3),
            p(0.95, 0.0),
            p(0.8, 0.0),
        ],
        // A, counter.
        vec![p(1.08, 0.45), p(1.32, 0.45), p(1.2, 0.85), p(1.08, 0.45)],
    ]
}

/// The test job scaled to `size` mm (the half width of its frame):
/// rectangle frame, three circles (half arcs and one full G3), the
/// outline of "LA", and a raster of short lines with varying power.
pub fn laser_job(size: f64) -> Job {
    let mut job = Job::default();
    let s = size;
    job.line("; laser job: frame, circles, text outline, raster");
    job.line("G00 G17 G40 G21 G54");
    job.line("G90");
    job.line("M4");
    // Frame.
    let frame = [
        [-s, -0.7 * s],
        [s, -0.7 * s],
        [s, 0.7 * s],
        [-s, 0.7 * s],
        [-s, -0.7 * s],
    ];
    job.polyline(&frame, 1500.0, 800.0);
    // Circles.
    job.circle([-0.6 * s, 0.35 * s], 0.25 * s, 1200.0, 600.0, true);
    job.circle([0.0, 0.35 * s], 0.2 * s, 1200.0, 600.0, false);
    job.circle([0.6 * s, 0.35 * s], 0.15 * s, 1200.0, 700.0, true);
    // Text outline.
    for outline in letters([-0.8 * s, -0.55 * s], 0.4 * s) {
        job.polyline(&outline, 1000.0, 1000.0);
    }
    // Raster: rows of short dashes, alternating direction, as image
    // engravers emit (power varies, G0 between rows).
    let rows = 5;
    for r in 0..rows {
        let y = -0.6 * s + r as f64 * 0.08 * s;
        let (x0, x1) = (0.2 * s, 0.9 * s);
        let dashes = 6;
        let mut xs: Vec<f64> = (0..=2 * dashes)
            .map(|k| x0 + (x1 - x0) * k as f64 / (2 * dashes) as f64)
            .collect();
        if r % 2 == 1 {
            xs.reverse();
        }
        job.rapid([xs[0], y]);
        for k in 0..2 * dashes {
            let lit = k % 2 == 0;
            let power = if lit {
                300.0 + 100.0 * (k / 2) as f64
            } else {
                0.0
            };
            job.line(format!(
                "G1 X{} Y{} F2000 S{}",
                num(xs[k + 1]),
                num(y),
                num(power)
            ));
            job.at = Some([xs[k + 1], y]);
            if lit {
                job.pieces.push(Piece::Line {
                    a: [xs[k], y],
                    b: [xs[k + 1], y],
                });
            }
        }
    }
    job.line("M5");
    job.rapid([0.0, 0.0]);
    job.line("M2");
    job
}

/// How well lit spot positions (mm) follow a toolpath.
#[derive(Debug, Clone, Copy)]
pub struct PathFit {
    /// Largest distance from a lit position to the toolpath, mm.
    pub worst_lit_mm: f64,
    /// Largest distance from a toolpath point to the nearest lit
    /// position, mm (how completely it was drawn).
    pub worst_missed_mm: f64,
    /// Lit positions checked.
    pub lit: usize,
    /// The toolpath piece with the worst gap (index into the pieces).
    pub worst_piece: usize,
    /// Where on the toolpath the worst gap is, mm.
    pub worst_gap_at: [f64; 2],
}

/// Compares lit spot positions with `pieces`.
pub fn fit(lit: &[[f64; 2]], pieces: &[Piece]) -> PathFit {
    let worst_lit_mm = lit
        .iter()
        .map(|&p| {
            pieces
                .iter()
                .map(|piece| piece.distance(p))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max);
    // Bucket the lit points on a 1 mm grid for the coverage search.
    let mut grid: std::collections::HashMap<(i64, i64), Vec<[f64; 2]>> = Default::default();
    for &p in lit {
        grid.entry((p[0].floor() as i64, p[1].floor() as i64))
            .or_default()
            .push(p);
    }
    let nearest = |q: [f64; 2]| {
        let (cx, cy) = (q[0].floor() as i64, q[1].floor() as i64);
        let mut best = f64::INFINITY;
        for dx in -2..=2 {
            for dy in -2..=2 {
                for p in grid.get(&(cx + dx, cy + dy)).into_iter().flatten() {
                    best = best.min((p[0] - q[0]).hypot(p[1] - q[1]));
                }
            }
        }
        best
    };
    let (worst_piece, worst_gap_at, worst_missed_mm) = pieces
        .iter()
        .enumerate()
        .flat_map(|(k, piece)| piece.points(0.5).into_iter().map(move |q| (k, q)))
        .map(|(k, q)| (k, q, nearest(q)))
        .fold((0, [0.0; 2], 0.0), |best, next| {
            if next.2 > best.2 { next } else { best }
        });
    PathFit {
        worst_lit_mm,
        worst_missed_mm,
        lit: lit.len(),
        worst_piece,
        worst_gap_at,
    }
}

/// A spot sample: time (µs or ns), board position (mm), laser lit.
pub type SpotMm = (u64, [f64; 2], bool);

/// What [`rapids_dark`] found for one G0.
#[derive(Debug, Clone, Copy)]
pub struct RapidSpan {
    /// Time the spot left the G0's start (last sample within the
    /// tolerance of it), same unit as the samples.
    pub left: u64,
    /// Time the spot reached the G0's target (first sample within the
    /// tolerance of it).
    pub arrived: u64,
    /// Samples strictly between the two.
    pub samples: usize,
    /// Of those, samples with the laser lit.
    pub lit: usize,
}

/// Maps every G0 of `rapids` longer than 3 × `tol_mm` onto the spot's
/// timeline `samples` (time order) and counts the lit samples on the way.
/// Each G0 spans from the last sample within `tol_mm` of its start (the
/// first sample when its start is unknown) to the first one after it
/// within `tol_mm` of its target; G0s are searched in order, each after
/// the previous one's arrival. Err when a G0's start or target is never
/// reached.
pub fn rapids_dark(
    samples: &[SpotMm],
    rapids: &[Rapid],
    tol_mm: f64,
) -> Result<Vec<RapidSpan>, String> {
    let near = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]) <= tol_mm;
    let mut cursor = 0;
    let mut spans = Vec::new();
    for (k, r) in rapids.iter().enumerate() {
        let at_start = match r.from {
            Some(from) if (from[0] - r.to[0]).hypot(from[1] - r.to[1]) <= 3.0 * tol_mm => continue,
            Some(from) => (cursor..samples.len())
                .find(|&i| near(samples[i].1, from))
                .ok_or_else(|| format!("G0 #{k} {r:?}: its start never reached"))?,
            None => cursor,
        };
        let arrival = (at_start..samples.len())
            .find(|&i| near(samples[i].1, r.to))
            .ok_or_else(|| {
                let closest = samples[at_start..]
                    .iter()
                    .map(|s| (s.1[0] - r.to[0]).hypot(s.1[1] - r.to[1]))
                    .fold(f64::INFINITY, f64::min);
                format!("G0 #{k} {r:?}: its target never reached (closest {closest:.3} mm)")
            })?;
        let left = r
            .from
            .and_then(|from| {
                (at_start..arrival)
                    .rev()
                    .find(|&i| near(samples[i].1, from))
            })
            .unwrap_or(at_start);
        let inside = &samples[left + 1..arrival];
        spans.push(RapidSpan {
            left: samples[left].0,
            arrived: samples[arrival].0,
            samples: inside.len(),
            lit: inside.iter().filter(|s| s.2).count(),
        });
        cursor = arrival;
    }
    Ok(spans)
}
