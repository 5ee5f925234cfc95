//! The board geometry of commanded G-code motions (lines, arcs as grbl
//! computes them, standing points) and distances to it, mm.

/// grbl's `ARC_ANGULAR_TRAVEL_EPSILON`, rad.
const FULL_CIRCLE_EPSILON_RAD: f64 = 5e-7;

/// The board path of one commanded motion, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Piece {
    /// A straight line (G0, G1).
    Line { a: [f64; 2], b: [f64; 2] },
    /// An arc about `centre` from angle `start_rad`, `sweep_rad` signed
    /// (positive counter-clockwise).
    Arc {
        centre: [f64; 2],
        radius: f64,
        start_rad: f64,
        sweep_rad: f64,
    },
    /// Standing at a point (G4).
    Point([f64; 2]),
}

impl Piece {
    /// Length, mm.
    pub(super) fn length_mm(&self) -> f64 {
        match *self {
            Piece::Line { a, b } => dist(a, b),
            Piece::Arc {
                radius, sweep_rad, ..
            } => radius * sweep_rad.abs(),
            Piece::Point(_) => 0.0,
        }
    }

    /// Where it starts, mm.
    pub(super) fn start(&self) -> [f64; 2] {
        match *self {
            Piece::Line { a, .. } => a,
            Piece::Arc {
                centre,
                radius,
                start_rad,
                ..
            } => on_circle(centre, radius, start_rad),
            Piece::Point(p) => p,
        }
    }

    /// Where it ends, mm.
    pub(super) fn end(&self) -> [f64; 2] {
        match *self {
            Piece::Line { b, .. } => b,
            Piece::Arc {
                centre,
                radius,
                start_rad,
                sweep_rad,
            } => on_circle(centre, radius, start_rad + sweep_rad),
            Piece::Point(p) => p,
        }
    }

    /// Distance of `p` from the piece, mm.
    pub(super) fn distance_mm(&self, p: [f64; 2]) -> f64 {
        match *self {
            Piece::Line { a, b } => {
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let len2 = dx * dx + dy * dy;
                let t = if len2 > 0.0 {
                    (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                dist(p, [a[0] + t * dx, a[1] + t * dy])
            }
            Piece::Arc {
                centre,
                radius,
                start_rad,
                sweep_rad,
            } => {
                let ang = (p[1] - centre[1]).atan2(p[0] - centre[0]);
                let along =
                    (sweep_rad.signum() * (ang - start_rad)).rem_euclid(std::f64::consts::TAU);
                if along <= sweep_rad.abs() {
                    (dist(p, centre) - radius).abs()
                } else {
                    let s = on_circle(centre, radius, start_rad);
                    dist(p, s).min(dist(p, self.end()))
                }
            }
            Piece::Point(q) => dist(p, q),
        }
    }
}

/// The point at `angle` (rad) on the circle about `centre`, mm.
fn on_circle(centre: [f64; 2], radius: f64, angle: f64) -> [f64; 2] {
    [
        centre[0] + radius * angle.cos(),
        centre[1] + radius * angle.sin(),
    ]
}

pub(super) fn dist(p: [f64; 2], q: [f64; 2]) -> f64 {
    (p[0] - q[0]).hypot(p[1] - q[1])
}

/// The arc of a G2 (`cw`)/G3 from `from` to `to` by I/J offsets or R, as
/// grbl computes it (`None`: grbl refuses it).
pub(super) fn arc(
    from: [f64; 2],
    to: [f64; 2],
    i: Option<f64>,
    j: Option<f64>,
    r: Option<f64>,
    cw: bool,
) -> Option<Piece> {
    let centre = match r {
        Some(r) => {
            let (x, y) = (to[0] - from[0], to[1] - from[1]);
            let h2 = 4.0 * r * r - x * x - y * y;
            if h2 < 0.0 || (x == 0.0 && y == 0.0) {
                return None;
            }
            let mut h = -h2.sqrt() / x.hypot(y);
            if !cw {
                h = -h;
            }
            if r < 0.0 {
                h = -h;
            }
            [from[0] + 0.5 * (x - y * h), from[1] + 0.5 * (y + x * h)]
        }
        None => [from[0] + i.unwrap_or(0.0), from[1] + j.unwrap_or(0.0)],
    };
    let (sx, sy) = (from[0] - centre[0], from[1] - centre[1]);
    let (ex, ey) = (to[0] - centre[0], to[1] - centre[1]);
    let mut sweep = (sx * ey - sy * ex).atan2(sx * ex + sy * ey);
    if cw && sweep >= -FULL_CIRCLE_EPSILON_RAD {
        sweep -= std::f64::consts::TAU;
    } else if !cw && sweep <= FULL_CIRCLE_EPSILON_RAD {
        sweep += std::f64::consts::TAU;
    }
    Some(Piece::Arc {
        centre,
        radius: sx.hypot(sy),
        start_rad: sy.atan2(sx),
        sweep_rad: sweep,
    })
}
