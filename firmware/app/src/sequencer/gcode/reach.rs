//! The soft-limit check's fast path: per driver, a rectangle of the board
//! proven reachable when the geometry changes, so that a block lying in it
//! needs none of the f64 IK calls of the exact check (~37 000 M4
//! instructions a point on the gimbal, 17 points an arc).
//!
//! Why a rectangle is proven by a few points: on each driver the reachable
//! set is, in board coordinates, convex along one axis and its limits are
//! monotone along the rectangle's edges except where a coordinate crosses
//! the driver's axis:
//!
//! * gimbal and stepper (exact or seed model, no board roll, no error
//!   model, board farther than OL): yaw depends on the board x alone,
//!   monotone; for a fixed x the pitch falls strictly with the board y
//!   (`dβ/dz = −(h + OL·z/√(r² − OL²))/r² < 0` as `h > OL`); along a
//!   horizontal edge the pitch is monotone in the horizontal distance `h`
//!   (`dβ/dh` has no zero off `z = OL`, where β is constant), which is
//!   monotone on each side of the x where the beam is level (`gy = 0`);
//! * galvo: the y mirror depends on y alone, monotone; the x mirror on
//!   `x / (√(d² + y²) + e)`, monotone in x and in |y|.
//!
//! The servo, soft-limit and DAC-code mappings are monotone in the joint
//! angles, so each limit holds on an interval. A rectangle whose corners
//! and whose edge points on those axes all pass the exact check is then
//! reachable everywhere. It is proven a [`MARGIN_MM`] larger than it is
//! used, so the exact check's rounding cannot refuse a point inside it.
//! The property test in `reach_tests.rs` checks this against the exact
//! check over random points, lines and arcs.

use crate::domain::Aimer;
use crate::grbl::{Block, PointMm};
use crate::sequencer::drivers::{Driver, Drivers};
use crate::sequencer::gcode::proven::{ProvenReach, SCALES};
use crate::sequencer::gcode::queue::{block_end, cm, point_at};
use crate::settings::Settings;

/// How much larger than it is used a rectangle is proven, mm.
const MARGIN_MM: f64 = 1e-3;

/// A rectangle of the board, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
struct BoxMm {
    lo: [f64; 2],
    hi: [f64; 2],
}

impl BoxMm {
    fn contains(&self, p: PointMm) -> bool {
        p.x_mm >= self.lo[0] && p.x_mm <= self.hi[0] && p.y_mm >= self.lo[1] && p.y_mm <= self.hi[1]
    }

    /// Whether the square of half side `r` about `c` lies inside.
    fn contains_square(&self, c: PointMm, r: f64) -> bool {
        c.x_mm - r >= self.lo[0]
            && c.x_mm + r <= self.hi[0]
            && c.y_mm - r >= self.lo[1]
            && c.y_mm + r <= self.hi[1]
    }
}

/// grbl's soft-limit check with the settings and geometry given.
#[derive(Clone, Copy)]
pub(in crate::sequencer) struct ReachCheck<'a> {
    /// The product's settings (board extent, limits).
    settings: &'a Settings,
    /// Their geometry.
    aimer: &'a Aimer,
}

impl<'a> ReachCheck<'a> {
    /// The check with `settings` and their geometry `aimer`.
    pub(in crate::sequencer) fn new(settings: &'a Settings, aimer: &'a Aimer) -> Self {
        Self { settings, aimer }
    }

    /// Whether every point of `block` is within grbl's soft limits for
    /// `drivers`: on the board (`$130` × `$131` about its centre) and
    /// within the reach of the actuator(s) (end points, and arcs along
    /// their sweep). `proven`: the rectangles [`Self::prove`] found.
    pub(in crate::sequencer) fn block(
        &self,
        block: &Block,
        drivers: Drivers,
        proven: ProvenReach,
    ) -> bool {
        self.surely(block, drivers, proven) || self.exactly(block, drivers)
    }

    /// [`Self::block`] point by point through the drivers' exact checks.
    pub(in crate::sequencer) fn exactly(&self, block: &Block, drivers: Drivers) -> bool {
        let Some(end) = block_end(block) else {
            return true;
        };
        let [half_width_mm, half_height_mm] = self.half_board_mm();
        let reachable = |p: PointMm| {
            let on_board = libm::fabs(p.x_mm) <= half_width_mm + 1e-9
                && libm::fabs(p.y_mm) <= half_height_mm + 1e-9;
            on_board && drivers.reach(self.aimer, self.settings, cm(p))
        };
        match block {
            Block::Arc { .. } => (0..=16).all(|k| reachable(point_at(block, k, 16))),
            _ => reachable(end),
        }
    }

    /// Half the board's extent (`$130` × `$131`), mm.
    fn half_board_mm(&self) -> [f64; 2] {
        self.settings.board_size_mm().map(|mm| 0.5 * mm)
    }

    /// The part of the board (about its centre) that `scale` of it is.
    fn board_box(&self, scale: f64) -> BoxMm {
        let [w, h] = self.half_board_mm();
        BoxMm {
            lo: [-w * scale, -h * scale],
            hi: [w * scale, h * scale],
        }
    }

    /// The drivers' fractions of the board proven reachable with the
    /// current settings (board extent, geometry, limits), each the
    /// largest of [`SCALES`] that passes.
    #[inline(never)]
    pub(in crate::sequencer) fn prove(&self) -> ProvenReach {
        let half = self.half_board_mm();
        let mut proven = ProvenReach::NONE;
        if !half.iter().all(|h| h.is_finite() && *h > 0.0) {
            return proven;
        }
        for driver in Driver::ALL {
            let Some(axis) = driver.monotone_axis(self.settings, self.aimer) else {
                continue;
            };
            let scale =
                (0..SCALES.len()).find(|&k| self.proves(driver, self.board_box(SCALES[k]), axis));
            proven = proven.with(driver.slot(), scale);
        }
        proven
    }
    /// Whether `driver` reaches every point of `b` grown by
    /// [`MARGIN_MM`]: its corners and its edges' points on `axis` pass the
    /// exact check.
    fn proves(&self, driver: Driver, b: BoxMm, axis: PointMm) -> bool {
        let lo = [b.lo[0] - MARGIN_MM, b.lo[1] - MARGIN_MM];
        let hi = [b.hi[0] + MARGIN_MM, b.hi[1] + MARGIN_MM];
        let reaches = |x_mm: f64, y_mm: f64| {
            driver.reaches(self.aimer, self.settings, cm(PointMm { x_mm, y_mm }))
        };
        let inside = |v: f64, i: usize| v > lo[i] && v < hi[i];
        let corners = [lo[0], hi[0]]
            .iter()
            .all(|&x| reaches(x, lo[1]) && reaches(x, hi[1]));
        let across_x = [axis.x_mm, 0.0]
            .iter()
            .all(|&x| !inside(x, 0) || (reaches(x, lo[1]) && reaches(x, hi[1])));
        let across_y = [axis.y_mm, 0.0]
            .iter()
            .all(|&y| !inside(y, 1) || (reaches(lo[0], y) && reaches(hi[0], y)));
        corners && across_x && across_y
    }

    /// Whether every point the soft-limit check looks at of `block` lies
    /// in the proven rectangle of every driver that draws (then the board
    /// and reach checks pass: the rectangles lie on the board). An arc:
    /// its end, and the circle about its centre through its start.
    pub(in crate::sequencer) fn surely(
        &self,
        block: &Block,
        drivers: Drivers,
        proven: ProvenReach,
    ) -> bool {
        let Some(end) = block_end(block) else {
            return false;
        };
        let circle = match *block {
            Block::Arc { arc, .. } => Some((arc.centre, arc.radius_mm)),
            _ => None,
        };
        drivers.iter().all(|d| {
            proven.scale(d.slot()).is_some_and(|k| {
                let b = self.board_box(k);
                b.contains(end) && circle.is_none_or(|(c, r)| b.contains_square(c, r))
            })
        })
    }
}

#[cfg(test)]
#[path = "reach_tests.rs"]
mod tests;
