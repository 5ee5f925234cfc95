//! Checks before a pattern or goto starts (and after a parameter change)
//! that what it draws is reachable: a bounded set of probe points aimed
//! at, a few per step of the caller.

use super::actuator::Actuator;
use super::aim::{Aimer, Target};
use super::error::PatternError;
use super::figure::{Figure, Pattern};
use super::path::pass_points;
use super::point::PointCm;
use super::units::{Unit, cm_from_mm};

/// Most points checked before a pattern starts (see [`PatternCheck`]).
pub const MAX_PROBES: usize = 16;

/// A point checked before a pattern starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Probe {
    /// Index within the pass when the probe is a point of the pass; `None`
    /// for a point of the ideal figure between interpolated points.
    pub(super) index: Option<usize>,
    /// The point, cm.
    pub(super) point: PointCm,
}

/// Checks one probe for every actuator that draws it.
fn check_probe(
    aimer: &Aimer,
    actuator: Actuator,
    pattern: &'static str,
    probe: Probe,
) -> Result<(), PatternError> {
    let point = probe.point;
    if actuator.uses_gimbal()
        && let Err(error) = aimer.aim(point)
    {
        return Err(match probe.index {
            Some(index) => PatternError::Unreachable {
                pattern,
                index,
                point,
                error,
            },
            None => PatternError::FigureUnreachable {
                pattern,
                point,
                error,
            },
        });
    }
    if actuator.uses_galvo() && !aimer.galvo_in_range(point) {
        return Err(PatternError::OutsideGalvoRange {
            pattern,
            index: probe.index.unwrap_or(0),
            point,
        });
    }
    Ok(())
}

/// Checks that a single target can be aimed at.
pub fn check_target(
    aimer: &Aimer,
    actuator: Actuator,
    target: &Target,
) -> Result<(), PatternError> {
    let probe = Probe {
        index: Some(0),
        point: target.point,
    };
    check_probe(aimer, actuator, "goto", probe)
}

/// `n` points of the ideal figure of a path with more points than
/// [`MAX_PROBES`]: its start, ends, corners and extremes, and points spread
/// evenly between them.
pub(super) fn figure_probes(figure: &Figure) -> heapless::Vec<Probe, MAX_PROBES> {
    let mut probes = heapless::Vec::new();
    let mut push = |x_cm: f64, y_cm: f64| {
        let _ = probes.push(Probe {
            index: None,
            point: PointCm { x_cm, y_cm },
        });
    };
    let lerp = |a: PointCm, b: PointCm, t: f64| {
        (
            a.x_cm + t * (b.x_cm - a.x_cm),
            a.y_cm + t * (b.y_cm - a.y_cm),
        )
    };
    match *figure {
        Figure::Line { from, to } => {
            let last = (MAX_PROBES - 1) as f64;
            for k in 0..MAX_PROBES {
                let (x, y) = lerp(from, to, k as f64 / last);
                push(x, y);
            }
        }
        Figure::Circle {
            centre, radius_cm, ..
        } => {
            // From the top (the start), every 22.5°: the four extremes too.
            for k in 0..MAX_PROBES {
                let angle = core::f64::consts::FRAC_PI_2
                    + core::f64::consts::TAU * k as f64 / MAX_PROBES as f64;
                let (sin, cos) = kinematics_core::numeric::trig::sin_cos(angle);
                push(centre.x_cm + radius_cm * cos, centre.y_cm + radius_cm * sin);
            }
        }
        Figure::Rect { a, b } => {
            let corners = [
                a,
                PointCm::new(b.x_cm, a.y_cm),
                b,
                PointCm::new(a.x_cm, b.y_cm),
            ];
            let per_edge = MAX_PROBES / 4;
            for (k, corner) in corners.iter().enumerate() {
                let next = corners[(k + 1) % 4];
                for j in 0..per_edge {
                    let (x, y) = lerp(*corner, next, j as f64 / per_edge as f64);
                    push(x, y);
                }
            }
        }
        Figure::Stroke(stroke) => stroke.points().for_each(|p| push(p.x_cm, p.y_cm)),
        Figure::Tuning { .. } => {}
    }
    probes
}

/// A check of a pattern before it starts, or of the running one after a
/// parameter change, done a few points at a time so that no step of the
/// caller holds the CPU for long (one gimbal IK point costs ~170 µs of
/// soft-float on the target).
///
/// It checks a bounded set of probe points: every point of a pattern of
/// at most [`MAX_PROBES`] points (the error names the first bad one),
/// else points spread over the whole figure (start, ends, corners,
/// extremes, evenly between). A figure that fails at a probe is refused
/// before anything moves or lights. Between probes the reachable region
/// need not be convex (pitch limits are conics on the board), so a run
/// also aims every point before it goes there and stops, laser off, with
/// an error at the first one it cannot reach.
#[derive(Debug, Clone)]
pub struct PatternCheck {
    pattern: &'static str,
    probes: heapless::Vec<Probe, MAX_PROBES>,
    next: usize,
}

impl PatternCheck {
    /// Prepares the check of `pattern` on `actuator`: the actuator and
    /// interpolation checks and the probe points (no IK yet; at most
    /// [`MAX_PROBES`] + 1 interpolated points).
    ///
    /// Errors: as [`check_pattern`], except for unreachable probes.
    pub fn new(pattern: &Pattern, aimer: &Aimer, actuator: Actuator) -> Result<Self, PatternError> {
        let name = pattern.name();
        let mut check = Self {
            pattern: name,
            probes: heapless::Vec::new(),
            next: 0,
        };
        if pattern.is_path() && actuator.uses_galvo() {
            if actuator.uses_gimbal() {
                return Err(PatternError::PathActuator { pattern: name });
            }
            let figure = pattern
                .figure()
                .ok_or(PatternError::Empty { pattern: name })?;
            check_galvo_bounds(&figure, aimer, name)?;
            return Ok(check);
        }
        let mut points = pass_points(pattern, aimer)?;
        for (index, target) in points.by_ref().take(MAX_PROBES).enumerate() {
            let _ = check.probes.push(Probe {
                index: Some(index),
                point: target.point,
            });
        }
        if check.probes.is_empty() {
            return Err(PatternError::Empty { pattern: name });
        }
        if points.next().is_none() {
            return Ok(check);
        }
        check.probes = match pattern.figure() {
            Some(figure) => figure_probes(&figure),
            None => {
                // Evenly spaced grid points, the first and the last among them.
                let last = aimer.grid_points(pattern).saturating_sub(1);
                (0..MAX_PROBES)
                    .filter_map(|k| {
                        let index = k * last / (MAX_PROBES - 1);
                        let target = aimer.grid_target(pattern, index)?;
                        Some(Probe {
                            index: Some(index),
                            point: target.point,
                        })
                    })
                    .collect()
            }
        };
        Ok(check)
    }

    /// Checks up to `max_points` more probes; `Ok(true)` once every probe
    /// passed.
    ///
    /// Errors: the first probe that cannot be aimed at or is outside the
    /// galvo's range.
    pub fn step(
        &mut self,
        aimer: &Aimer,
        actuator: Actuator,
        max_points: usize,
    ) -> Result<bool, PatternError> {
        let end = self.next.saturating_add(max_points).min(self.probes.len());
        while self.next < end {
            let probe = self.probes[self.next];
            check_probe(aimer, actuator, self.pattern, probe)?;
            self.next += 1;
        }
        Ok(self.next >= self.probes.len())
    }
}

/// The galvo marks a path itself: the corners of its bounding box (as the
/// galvo takes them, mm) must be in its DAC range.
fn check_galvo_bounds(
    figure: &Figure,
    aimer: &Aimer,
    pattern: &'static str,
) -> Result<(), PatternError> {
    for (index, [x_mm, y_mm]) in figure.bounds(Unit::GalvoMm).into_iter().enumerate() {
        let point = PointCm::new(cm_from_mm(x_mm), cm_from_mm(y_mm));
        if !aimer.galvo_in_range(point) {
            return Err(PatternError::OutsideGalvoRange {
                pattern,
                index,
                point,
            });
        }
    }
    Ok(())
}

/// Checks before a pattern starts that it has points and that it is
/// reachable at its probe points (see [`PatternCheck`]), all at once; the
/// error names the first bad point.
pub fn check_pattern(
    pattern: &Pattern,
    aimer: &Aimer,
    actuator: Actuator,
) -> Result<(), PatternError> {
    let mut check = PatternCheck::new(pattern, aimer, actuator)?;
    check.step(aimer, actuator, usize::MAX).map(|_| ())
}
