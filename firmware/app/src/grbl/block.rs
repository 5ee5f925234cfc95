//! What a G-code line asks the machine to do: the [`Block`] vocabulary the
//! motion queue consumes. Coordinates are board millimetres (origin at the
//! board centre, X right, Y up), absolute, after units, distance mode and
//! work offsets are applied; feeds are mm/min.

use core::f64::consts::TAU;
use kinematics_core::numeric::trig;

/// A point on the board plane, mm.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PointMm {
    /// Right, mm.
    pub x_mm: f64,
    /// Up, mm.
    pub y_mm: f64,
}

impl PointMm {
    /// The origin (board centre).
    pub const ZERO: PointMm = PointMm {
        x_mm: 0.0,
        y_mm: 0.0,
    };

    /// Distance to `other`, mm.
    pub fn distance_to(self, other: PointMm) -> f64 {
        kinematics_core::numeric::hypot(other.x_mm - self.x_mm, other.y_mm - self.y_mm)
    }
}

/// Laser (spindle) mode: M5, M3 or M4.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SpindleMode {
    /// M5: laser off.
    #[default]
    Off,
    /// M3: constant power S while moving with G1/G2/G3.
    Constant,
    /// M4: dynamic power, S scaled by the actual speed over the programmed
    /// feed (dark when stopped).
    Dynamic,
}

/// The laser setting a feed motion or a dwell runs with.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Laser {
    /// M3/M4/M5.
    pub mode: SpindleMode,
    /// Programmed power S, in the units of `$30` (max) / `$31` (min).
    pub power: f64,
}

impl Laser {
    /// Output fraction 0..=1 for this setting (before overrides and M4
    /// speed scaling), grbl's linear map of S between `$31` (`s_min`) and
    /// `$30` (`s_max`): S at or below `s_min` is 0 unless `s_min` is 0, at or
    /// above `s_max` is 1. M5 is 0.
    pub fn fraction(self, s_min: f64, s_max: f64) -> f64 {
        let span = s_max - s_min;
        if self.mode == SpindleMode::Off || self.power <= 0.0 || span.is_nan() || span <= 0.0 {
            return 0.0;
        }
        ((self.power - s_min) / (s_max - s_min)).clamp(0.0, 1.0)
    }
}

/// A circular arc in the board plane (G2/G3 after grbl's checks).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Arc {
    /// Start, mm.
    pub from: PointMm,
    /// End, mm.
    pub to: PointMm,
    /// Centre, mm.
    pub centre: PointMm,
    /// Radius at the start, mm.
    pub radius_mm: f64,
    /// Signed angle swept, rad: positive counter-clockwise (G3), negative
    /// clockwise (G2); a full circle is ±2π.
    pub sweep_rad: f64,
}

/// Slowest feed a motion runs at, mm/min: grbl 1.1's `MINIMUM_FEED_RATE`
/// (config.h, applied in its planner). A slower programmed feed (or a
/// G93 inverse-time feed that works out slower) is raised to this, on
/// every actuator, so a lit spot on a feed move never creeps slower than
/// 1 mm/min (1/60 mm/s): it leaves any 0.1 mm spot within 6 s.
pub const MIN_FEED_MM_MIN: f64 = 1.0;

/// The feed a motion runs at for a programmed `feed_mm_min` (> 0): never
/// below [`MIN_FEED_MM_MIN`], mm/min.
pub fn clamped_feed_mm_min(feed_mm_min: f64) -> f64 {
    feed_mm_min.max(MIN_FEED_MM_MIN)
}

/// grbl's `ARC_ANGULAR_TRAVEL_EPSILON`, rad: an arc ending within this
/// angle of its start is a full circle.
const FULL_CIRCLE_EPSILON_RAD: f64 = 5e-7;

impl Arc {
    /// The arc from `from` around `centre` to `to`, clockwise for G2.
    pub fn new(from: PointMm, to: PointMm, centre: PointMm, clockwise: bool) -> Arc {
        let (sx, sy) = (from.x_mm - centre.x_mm, from.y_mm - centre.y_mm);
        let (ex, ey) = (to.x_mm - centre.x_mm, to.y_mm - centre.y_mm);
        let mut sweep = libm::atan2(sx * ey - sy * ex, sx * ex + sy * ey);
        if clockwise && sweep >= -FULL_CIRCLE_EPSILON_RAD {
            sweep -= TAU;
        } else if !clockwise && sweep <= FULL_CIRCLE_EPSILON_RAD {
            sweep += TAU;
        }
        Arc {
            from,
            to,
            centre,
            radius_mm: kinematics_core::numeric::hypot(sx, sy),
            sweep_rad: sweep,
        }
    }

    /// Path length, mm.
    pub fn length_mm(&self) -> f64 {
        libm::fabs(self.sweep_rad) * self.radius_mm
    }

    /// The point at `fraction` (0..=1) of the sweep; exactly `to` at 1.
    pub fn point_at(&self, fraction: f64) -> PointMm {
        if fraction >= 1.0 {
            return self.to;
        }
        let angle = self.sweep_rad * fraction.max(0.0);
        let (sin, cos) = trig::sin_cos(angle);
        let (sx, sy) = (
            self.from.x_mm - self.centre.x_mm,
            self.from.y_mm - self.centre.y_mm,
        );
        PointMm {
            x_mm: self.centre.x_mm + sx * cos - sy * sin,
            y_mm: self.centre.y_mm + sx * sin + sy * cos,
        }
    }

    /// Number of equal straight segments so that no chord strays more than
    /// `tolerance_mm` from the arc (`$12`; grbl's estimate can exceed it
    /// slightly, this count never does), at least 1 and at most `max`.
    pub fn segment_count(&self, tolerance_mm: f64, max: u32) -> u32 {
        let r = self.radius_mm;
        if !(tolerance_mm > 0.0 && r > tolerance_mm) {
            return 1;
        }
        // A chord over angle θ strays r·(1 − cos(θ/2)) from the arc.
        let max_angle = 2.0 * trig::acos(1.0 - tolerance_mm / r);
        let n = libm::ceil(libm::fabs(self.sweep_rad) / max_angle);
        if n.is_nan() || n < 1.0 {
            return 1;
        }
        n.min(f64::from(max.max(1))) as u32
    }
}

/// One executable step of a G-code line, in execution order.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Block {
    /// G0: move at the maximum rate, laser dark (laser mode).
    Rapid {
        /// Start, mm.
        from: PointMm,
        /// End, mm.
        to: PointMm,
    },
    /// G1: straight feed move.
    Line {
        /// Start, mm.
        from: PointMm,
        /// End, mm.
        to: PointMm,
        /// Feed, mm/min (G93 already converted), > 0.
        feed_mm_min: f64,
        /// Laser during the move.
        laser: Laser,
    },
    /// G2/G3: arc feed move.
    Arc {
        /// The arc.
        arc: Arc,
        /// Feed along the arc, mm/min, > 0.
        feed_mm_min: f64,
        /// Laser during the move.
        laser: Laser,
    },
    /// G4: wait once the queue ahead has finished, s.
    Dwell {
        /// Duration, s.
        seconds: f64,
        /// Laser during the dwell: M5 unless the modal motion is G1/G2/G3
        /// (grbl's laser mode); M4 means dark too, as the speed is 0.
        laser: Laser,
    },
    /// M0: pause (a feed hold that `~` resumes) after the queue ahead.
    Pause,
    /// M2/M30: program end; the parser's modal state is already reset.
    End,
    /// `$J=`: a jog move (changes no modal state), laser dark.
    Jog {
        /// Start, mm.
        from: PointMm,
        /// End, mm.
        to: PointMm,
        /// Feed, mm/min, > 0.
        feed_mm_min: f64,
    },
}

/// The blocks of one line, in execution order (dwell, motion, program flow).
pub type Blocks = heapless::Vec<Block, 3>;

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    fn p(x_mm: f64, y_mm: f64) -> PointMm {
        PointMm { x_mm, y_mm }
    }

    #[test]
    fn arc_sweeps_follow_direction_and_full_circles() {
        let half_ccw = Arc::new(p(10.0, 0.0), p(-10.0, 0.0), PointMm::ZERO, false);
        assert!((half_ccw.sweep_rad - PI).abs() < 1e-12);
        let three_quarter_cw = Arc::new(p(10.0, 0.0), p(0.0, 10.0), PointMm::ZERO, true);
        assert!((three_quarter_cw.sweep_rad + 1.5 * PI).abs() < 1e-12);
        let full = Arc::new(p(10.0, 0.0), p(10.0, 0.0), PointMm::ZERO, true);
        assert!((full.sweep_rad + TAU).abs() < 1e-12);
        assert!((full.length_mm() - TAU * 10.0).abs() < 1e-9);
        let quarter = half_ccw.point_at(0.5);
        assert!(quarter.distance_to(p(0.0, 10.0)) < 1e-12);
        assert_eq!(half_ccw.point_at(1.0), p(-10.0, 0.0));
    }

    #[test]
    fn segment_count_keeps_chords_within_tolerance() {
        let circle = Arc::new(p(10.0, 0.0), p(10.0, 0.0), PointMm::ZERO, false);
        let n = circle.segment_count(0.002, 100_000);
        let sagitta = 10.0 * (1.0 - libm::cos(PI / f64::from(n)));
        assert!(sagitta <= 0.002, "{n} segments: sagitta {sagitta}");
        assert_eq!(circle.segment_count(0.0, 100), 1);
        assert_eq!(circle.segment_count(f64::NAN, 100), 1);
        assert_eq!(circle.segment_count(1e-12, 50), 50);
    }

    #[test]
    fn laser_fraction_maps_s_between_min_and_max() {
        let on = |power| Laser {
            mode: SpindleMode::Constant,
            power,
        };
        assert_eq!(on(500.0).fraction(0.0, 1000.0), 0.5);
        assert_eq!(on(2000.0).fraction(0.0, 1000.0), 1.0);
        assert_eq!(on(0.0).fraction(0.0, 1000.0), 0.0);
        assert_eq!(on(500.0).fraction(0.0, 0.0), 0.0);
        let off = Laser {
            mode: SpindleMode::Off,
            power: 1000.0,
        };
        assert_eq!(off.fraction(0.0, 1000.0), 0.0);
    }
}
