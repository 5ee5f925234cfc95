//! Counting a curve's pieces without the f64 IK and FK per piece (~30 000
//! M4 instructions each, doubled with every doubling of the count): the
//! stepper's exact model with OL = 0 in single precision and without
//! trigonometry, for the pan/tilt's joint geometry is a ray from O. A leaf:
//! it takes the geometry, the limits and the curve's shape as arguments.
//!
//! With OL = 0, the beam to the global point `(X, y, z)` has yaw `atan2(y,
//! X)` and pitch `−atan2(z, h)` (`h = √(X² + y²)`), so the sines and
//! cosines of both joints come from the point by square roots; the joint
//! midpoint of two ends (the mean of their angles) is the bisector of
//! their unit vectors; the spot for joints `(a, b)` is `(X, X·tan a,
//! −X·tan b / cos a)`. The joint limits become limits on `y/X` and `−z/h`
//! (their tangents), shrunk by [`LIMIT_MARGIN_DEG`].
//!
//! Single precision errs by ~1e-4 mm on the deviation (points within
//! ~±50 cm), so a piece's pass or fail is taken here only when its
//! deviation lies more than [`UNSURE_SHARE`] of the tolerance (the
//! stepper's 0.05 mm) from it; the few closer are decided through the f64
//! IK and FK, piece by piece: the count is the exact check's, every round
//! deciding the same way. A piece end near a limit, or a geometry outside
//! these assumptions, leaves the count to the exact check.

use kinematics_core::frames::BoardPoint;
use kinematics_core::gimbal::{Gimbal, GimbalModel};
use kinematics_core::numeric::trig;
use kinematics_core::path::Shape;
use kinematics_core::servo::ServoAxis;
use kinematics_core::sqrt_f32;

/// How far inside the joint limits a piece end must lie here, deg.
const LIMIT_MARGIN_DEG: f64 = 0.01;
/// How far (a share of the tolerance) the deviation must lie from the
/// tolerance for single precision to decide (it errs by < 0.2 % of it).
const UNSURE_SHARE: f32 = 0.02;
/// Unsure pieces of a round kept by index (beyond them, every piece from
/// the next unsure one is decided through f64).
const UNSURE_KEPT: usize = 8;
/// Highest joint limit handled, deg (tangents stay finite).
const MAX_LIMIT_DEG: f64 = 85.0;

/// The stepper's joint geometry in single precision.
#[derive(Debug, Clone, Copy)]
pub(super) struct Joints32 {
    /// Global x of the board plane, cm.
    plane_x: f32,
    /// Board offsets, cm, and pose (roll sine and cosine, dy, dz).
    offset: [f32; 2],
    roll: [f32; 2],
    shift: [f32; 2],
    /// Tangents of the yaw limits (low, high), shrunk.
    yaw_tan: [f32; 2],
    /// Tangents of the pitch limits (low, high), shrunk.
    pitch_tan: [f32; 2],
}

/// A piece end: the point's joint sines and cosines.
#[derive(Clone, Copy)]
struct End {
    /// Yaw (cos, sin).
    yaw: [f32; 2],
    /// Pitch (cos, sin).
    pitch: [f32; 2],
}

impl Joints32 {
    /// The geometry of `gimbal` within the stepper's soft limits
    /// `min_deg`..`max_deg` (`[pan, tilt]`, joint degrees), or `None` when
    /// it is not the exact model with OL = 0 (or its limits lie beyond
    /// ±[`MAX_LIMIT_DEG`]).
    #[inline(never)]
    pub(super) fn of(gimbal: &Gimbal, min_deg: [f64; 2], max_deg: [f64; 2]) -> Option<Self> {
        let g = &gimbal.geometry;
        if gimbal.model != GimbalModel::Exact || g.ol_cm != 0.0 {
            return None;
        }
        let frame = &g.frame;
        let plane_x = frame.plane_x_cm().ok()?;
        let (s, c) = trig::sin_cos(frame.pose.roll_deg.to_radians());
        let limits = |i: usize, servo: &ServoAxis| -> Option<[f32; 2]> {
            let sign = servo.direction.sign() * servo.scale;
            let (a, b) = (
                (servo.min_deg - servo.zero_deg) / sign,
                (servo.max_deg - servo.zero_deg) / sign,
            );
            let lo = a.min(b).max(min_deg[i]) + LIMIT_MARGIN_DEG;
            let hi = a.max(b).min(max_deg[i]) - LIMIT_MARGIN_DEG;
            let range = -MAX_LIMIT_DEG..=MAX_LIMIT_DEG;
            let tan = |deg: f64| {
                let (s, c) = trig::sin_cos(deg.to_radians());
                (s / c) as f32
            };
            (lo < hi && range.contains(&lo) && range.contains(&hi)).then(|| [tan(lo), tan(hi)])
        };
        Some(Self {
            plane_x: plane_x as f32,
            offset: [frame.x_offset_cm as f32, frame.y_offset_cm as f32],
            roll: [s as f32, c as f32],
            shift: [frame.pose.dy_cm as f32, frame.pose.dz_cm as f32],
            yaw_tan: limits(0, &g.yaw)?,
            pitch_tan: limits(1, &g.pitch)?,
        })
    }

    /// The joints of board point `p` (cm), or `None` near or beyond a
    /// limit.
    fn end(&self, p: [f32; 2]) -> Option<End> {
        let [s, c] = self.roll;
        let (u, v) = (p[0] + self.offset[0], p[1] + self.offset[1]);
        let y = self.shift[0] - c * u - s * v;
        let z = self.shift[1] - s * u + c * v;
        let x = self.plane_x;
        let h = sqrt_f32(x * x + y * y);
        let r = sqrt_f32(h * h + z * z);
        let (yaw_tan, pitch_tan) = (y / x, -z / h);
        let within = |t: f32, lim: [f32; 2]| t >= lim[0] && t <= lim[1];
        (within(yaw_tan, self.yaw_tan) && within(pitch_tan, self.pitch_tan)).then_some(End {
            yaw: [x / h, y / h],
            pitch: [h / r, -z / r],
        })
    }

    /// The board point (cm) the spot lands on for the joints midway
    /// between `a` and `b`.
    fn mid_spot(&self, a: End, b: End) -> Option<[f32; 2]> {
        let yaw = [a.yaw[0] + b.yaw[0], a.yaw[1] + b.yaw[1]];
        let pitch = [a.pitch[0] + b.pitch[0], a.pitch[1] + b.pitch[1]];
        // Both halves within ±85°: the sums' cosines are well above 0.
        if yaw[0] <= 0.1 || pitch[0] <= 0.1 {
            return None;
        }
        let yaw_cos = yaw[0] / sqrt_f32(yaw[0] * yaw[0] + yaw[1] * yaw[1]);
        let x = self.plane_x;
        let gy = x * yaw[1] / yaw[0] - self.shift[0];
        let gz = -x * (pitch[1] / pitch[0]) / yaw_cos - self.shift[1];
        let [s, c] = self.roll;
        let u = -(c * gy + s * gz);
        let v = -s * gy + c * gz;
        Some([u - self.offset[0], v - self.offset[1]])
    }

    /// The fewest pieces (a power of two from `fewest`, at most
    /// `max_pieces`) of `shape` whose joint-space midpoints lie within
    /// `tolerance_mm` of it, as the exact check counts them: a piece
    /// whose deviation lies within [`UNSURE_SHARE`] of the tolerance is
    /// decided by `exact_mm(k, pieces)` (piece `k` of `pieces`, its
    /// deviation in mm through the f64 IK and FK). `None`: left to the
    /// exact check (an end near a limit, `exact_mm` failing).
    #[inline(never)]
    pub(super) fn pieces(
        &self,
        shape: Shape,
        fewest: u32,
        tolerance_mm: f64,
        max_pieces: u32,
        exact_mm: &dyn Fn(u32, u32) -> Option<f64>,
    ) -> Option<u32> {
        let mut pieces = fewest;
        let tolerance_cm = crate::domain::units::cm_from_mm(tolerance_mm) as f32;
        let unsure_cm = UNSURE_SHARE * tolerance_cm;
        loop {
            let mut passes = true;
            // The unsure pieces: the first few, and the first of the rest.
            let mut unsure = [0u32; UNSURE_KEPT];
            let mut count = 0;
            let mut more = None;
            self.deviations_cm(shape, pieces, &mut |k, deviation_cm| {
                if (deviation_cm - tolerance_cm).abs() <= unsure_cm {
                    match unsure.get_mut(count) {
                        Some(slot) => {
                            *slot = k;
                            count += 1;
                        }
                        None => more = more.or(Some(k)),
                    }
                } else if deviation_cm > tolerance_cm {
                    passes = false;
                }
            })?;
            if passes {
                let rest = more.map(|first| first..=pieces).into_iter().flatten();
                for k in unsure.into_iter().take(count).chain(rest) {
                    if exact_mm(k, pieces)? > tolerance_mm {
                        passes = false;
                        break;
                    }
                }
            }
            if passes || pieces >= max_pieces {
                return Some(pieces);
            }
            pieces *= 2;
        }
    }

    /// The distance of each joint-space midpoint of `pieces` equal pieces
    /// of `shape` from it, cm, to `each(k, deviation)` (`k` from 1);
    /// `None` for an end near or beyond a limit.
    fn deviations_cm(
        &self,
        shape: Shape,
        pieces: u32,
        each: &mut dyn FnMut(u32, f32),
    ) -> Option<()> {
        let n = f64::from(pieces);
        let mut a = self.end(point32(shape.point_at(0.0)))?;
        match shape {
            Shape::Line { from, to } => {
                let (f, t) = (point32(from), point32(to));
                for k in 1..=pieces {
                    let b = self.end(point32(shape.point_at(f64::from(k) / n)))?;
                    each(k, to_segment_cm(self.mid_spot(a, b)?, f, t));
                    a = b;
                }
            }
            Shape::Arc {
                centre,
                radius_cm,
                start_rad,
                sweep_rad,
            } => {
                // The ends by rotation in double precision (no drift).
                let (s, c) = trig::sin_cos(sweep_rad / n);
                let (start_sin, start_cos) = trig::sin_cos(start_rad);
                let (mut ex, mut ey) = (radius_cm * start_cos, radius_cm * start_sin);
                let (cx, cy, r) = (centre.x_cm as f32, centre.y_cm as f32, radius_cm as f32);
                for k in 1..=pieces {
                    (ex, ey) = (ex * c - ey * s, ex * s + ey * c);
                    let b =
                        self.end(point32(BoardPoint::new(centre.x_cm + ex, centre.y_cm + ey)))?;
                    let m = self.mid_spot(a, b)?;
                    let (dx, dy) = (m[0] - cx, m[1] - cy);
                    each(k, (sqrt_f32(dx * dx + dy * dy) - r).abs());
                    a = b;
                }
            }
        }
        Some(())
    }
}

fn point32(p: BoardPoint) -> [f32; 2] {
    [p.x_cm as f32, p.y_cm as f32]
}

/// Distance from `p` to the segment `a`–`b`, cm.
fn to_segment_cm(p: [f32; 2], a: [f32; 2], b: [f32; 2]) -> f32 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (ox, oy) = (p[0] - (a[0] + t * dx), p[1] - (a[1] + t * dy));
    sqrt_f32(ox * ox + oy * oy)
}

#[cfg(test)]
#[path = "fast_tests.rs"]
mod tests;
