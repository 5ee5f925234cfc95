//! From commands to servo angles: the points of each pattern and path, and
//! the aiming chain board point → error-model compensation → gimbal IK
//! (exact or seed) → servo mapping → FashionStar wire value. All geometry
//! is `kinematics-core`; this module only builds its inputs from
//! [`Settings`].

use kinematics_core as kc;
use kinematics_core::{BoardPoint, Criterion, ErrorModel, Gimbal, Grid, GridIndex};

use crate::command::{Actuator, AimModel, Pattern, PointCm};
use crate::galvo::GalvoPath;
use crate::settings::{AxisSettings, Settings};
use crate::text::Fixed;

/// One point the sequencer visits.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Target {
    /// Board point, cm.
    pub point: PointCm,
    /// Grid index `(xi, yi)` when the point is a grid point.
    pub grid: Option<(i8, i8)>,
}

/// Where the servos go for a target.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Aim {
    /// Yaw joint angle, deg.
    pub yaw_deg: f64,
    /// Pitch joint angle, deg.
    pub pitch_deg: f64,
    /// Yaw servo angle on the wire, 0.1 deg.
    pub yaw_wire: i16,
    /// Pitch servo angle on the wire, 0.1 deg.
    pub pitch_wire: i16,
}

fn servo_axis(axis: &AxisSettings) -> kc::ServoAxis {
    kc::ServoAxis {
        direction: kc::Direction::from_sign(axis.direction).unwrap_or_default(),
        scale: axis.scale,
        zero_deg: axis.zero_deg,
        min_deg: axis.min_deg,
        max_deg: axis.max_deg,
    }
}

/// The calibrated gimbal described by `settings`, aimed with `model`.
pub fn gimbal(settings: &Settings, model: AimModel) -> Gimbal {
    Gimbal {
        model: match model {
            AimModel::Exact => kc::GimbalModel::Exact,
            AimModel::Seed => kc::GimbalModel::Seed,
        },
        geometry: kc::GimbalGeometry {
            ol_cm: settings.ol_cm,
            frame: kc::BoardFrame {
                oq_cm: settings.oq_cm,
                x_offset_cm: 0.0,
                y_offset_cm: 0.0,
                pose: kc::BoardPose {
                    roll_deg: settings.board_roll_deg,
                    ..kc::BoardPose::default()
                },
            },
            yaw: servo_axis(&settings.yaw),
            pitch: servo_axis(&settings.pitch),
        },
    }
}

/// The grid described by `settings` (its offsets move the grid origin on
/// the board).
pub fn grid(settings: &Settings) -> Grid {
    Grid {
        pitch_cm: settings.grid_pitch_cm,
        cols: settings.grid_cols,
        rows: settings.grid_rows,
        x_offset_cm: settings.x_offset_cm,
        y_offset_cm: settings.y_offset_cm,
    }
}

/// The loaded error model (mm coefficients).
pub fn error_model(settings: &Settings) -> ErrorModel {
    ErrorModel::new(settings.err_dx, settings.err_dy)
}

fn board(p: PointCm) -> BoardPoint {
    BoardPoint::new(p.x_cm, p.y_cm)
}

fn point_cm(p: BoardPoint) -> PointCm {
    PointCm {
        x_cm: p.x_cm,
        y_cm: p.y_cm,
    }
}

/// The aiming chain of one set of settings and one model, built once and
/// used for many points (a check of many points does not rebuild the
/// gimbal and error model from [`Settings`] for each of them).
#[derive(Debug, Clone, Copy)]
pub struct Aimer {
    error_model: ErrorModel,
    gimbal: Gimbal,
}

impl Aimer {
    /// The chain described by `settings`, aimed with `model`.
    pub fn new(settings: &Settings, model: AimModel) -> Self {
        Self {
            error_model: error_model(settings),
            gimbal: gimbal(settings, model),
        }
    }

    /// Servo angles that put the spot on board point `point` (cm); see
    /// [`aim`].
    pub fn aim(&self, point: PointCm) -> Result<Aim, kc::Error> {
        let corrected = self.error_model.compensate_board(board(point))?;
        let joints = self.gimbal.ik(corrected)?;
        let wire = self.gimbal.to_wire(joints)?;
        Ok(Aim {
            yaw_deg: joints.yaw_deg,
            pitch_deg: joints.pitch_deg,
            yaw_wire: wire.yaw,
            pitch_wire: wire.pitch,
        })
    }
}

/// Servo angles that put the spot on board point `point` (cm): the error
/// model pre-compensates the point, the gimbal IK of `model` gives the
/// joint angles, the servo mapping the wire values (limits checked).
///
/// Errors: unreachable or non-finite targets, servo limits, a diverging
/// error model — never NaN angles.
pub fn aim(settings: &Settings, model: AimModel, point: PointCm) -> Result<Aim, kc::Error> {
    Aimer::new(settings, model).aim(point)
}

/// The grid point `(xi, yi)`.
///
/// Errors: index outside the configured grid.
pub fn grid_point(settings: &Settings, xi: i8, yi: i8) -> Result<Target, kc::Error> {
    let point = grid(settings).point(GridIndex { xi, yi })?;
    Ok(Target {
        point: point_cm(point),
        grid: Some((xi, yi)),
    })
}

/// The grid pattern behind a grid [`Pattern`].
fn grid_pattern(pattern: &Pattern) -> Option<kc::Pattern> {
    match pattern {
        Pattern::Grid(grid) => Some(*grid),
        Pattern::Line { .. }
        | Pattern::Circle { .. }
        | Pattern::Rect { .. }
        | Pattern::Tuning { .. } => None,
    }
}

/// The galvo path (mm) of a path pattern (cm).
pub fn galvo_path(pattern: &Pattern) -> Option<GalvoPath> {
    let mm = |p: PointCm| [(p.x_cm * 10.0) as f32, (p.y_cm * 10.0) as f32];
    Some(match *pattern {
        Pattern::Line { from, to } => GalvoPath::Line {
            from_mm: mm(from),
            to_mm: mm(to),
        },
        Pattern::Circle {
            centre,
            radius_cm,
            rotation,
        } => GalvoPath::Circle {
            centre_mm: mm(centre),
            radius_mm: (radius_cm * 10.0) as f32,
            ccw: rotation == kc::Rotation::Ccw,
        },
        Pattern::Rect { a, b } => GalvoPath::Rect {
            a_mm: mm(a),
            b_mm: mm(b),
        },
        Pattern::Tuning { centre, size_cm } => GalvoPath::Tuning {
            centre_mm: mm(centre),
            half_size_mm: (size_cm * 5.0) as f32,
        },
        Pattern::Grid(_) => return None,
    })
}

/// The points of a path pattern, interpolated point by point (midpoint
/// criterion: within half a step per axis of the ideal path).
#[derive(Debug, Clone, Copy)]
enum PathPoints {
    Line(kc::LineSteps),
    Arc(kc::ArcSteps),
    Rect(kc::RectSteps),
}

impl Iterator for PathPoints {
    type Item = BoardPoint;

    fn next(&mut self) -> Option<BoardPoint> {
        match self {
            PathPoints::Line(steps) => steps.next(),
            PathPoints::Arc(steps) => steps.next(),
            PathPoints::Rect(steps) => steps.next(),
        }
    }
}

fn path_points(pattern: &Pattern, settings: &Settings) -> Option<Result<PathPoints, kc::Error>> {
    let step = settings.path_step_cm;
    let criterion = Criterion::Midpoint;
    Some(match *pattern {
        Pattern::Line { from, to } => {
            kc::LineSteps::new(board(from), board(to), step, criterion).map(PathPoints::Line)
        }
        Pattern::Circle {
            centre,
            radius_cm,
            rotation,
        } => kc::ArcSteps::circle(board(centre), radius_cm, rotation, step, criterion)
            .map(PathPoints::Arc),
        Pattern::Rect { a, b } => {
            kc::RectSteps::new(board(a), board(b), step, criterion).map(PathPoints::Rect)
        }
        _ => return None,
    })
}

/// Point `index` (from 0) of one pass of grid pattern `pattern` on the
/// grid of `settings`, in O(1); `None` past the end of the pass or for a
/// path (its points come from a [`PathCursor`]).
pub fn grid_target(pattern: &Pattern, index: usize, settings: &Settings) -> Option<Target> {
    let grid_pattern = grid_pattern(pattern)?;
    let grid = grid(settings);
    let idx = grid_pattern.indices(&grid).nth(index)?;
    let point = grid.point(idx).ok()?;
    Some(Target {
        point: point_cm(point),
        grid: Some((idx.xi, idx.yi)),
    })
}

/// Where a run is in one pass of a path pattern: the interpolator's state
/// and its current point. The next point costs O(1): nothing walks the
/// path from its start. The pass keeps the step it started with
/// (`path.step_cm` applies from the next pass).
#[derive(Debug, Clone, Copy)]
pub struct PathCursor {
    points: PathPoints,
    current: BoardPoint,
}

impl PathCursor {
    /// At the first point of a pass of `pattern` with `settings`; `None`
    /// for grid patterns and the tuning figure (galvo only).
    ///
    /// Errors: the path cannot be interpolated (radius below one step, too
    /// many steps, non-finite input).
    pub fn start(pattern: &Pattern, settings: &Settings) -> Option<Result<Self, kc::Error>> {
        Some(path_points(pattern, settings)?.and_then(|mut points| {
            // Every interpolator yields its start point first.
            let current = points.next().ok_or(kc::Error::PathTooShort)?;
            Ok(Self { points, current })
        }))
    }

    /// The current point.
    pub fn target(&self) -> Target {
        Target {
            point: point_cm(self.current),
            grid: None,
        }
    }

    /// Moves to the next point; `false` (staying on the last point) at the
    /// end of the pass.
    pub fn advance(&mut self) -> bool {
        match self.points.next() {
            Some(point) => {
                self.current = point;
                true
            }
            None => false,
        }
    }
}

/// Every point of one pass of `pattern` in order (grid points on the grid
/// of `settings`), for checks and tools; a run itself steps through them
/// with [`grid_target`] and [`PathCursor`].
///
/// Errors: the path cannot be interpolated; the tuning figure (galvo only).
pub fn pass_points(
    pattern: &Pattern,
    settings: &Settings,
) -> Result<impl Iterator<Item = Target>, PatternError> {
    let name = pattern.name();
    let mut path = match PathCursor::start(pattern, settings) {
        Some(Ok(cursor)) => Some(cursor),
        Some(Err(error)) => {
            return Err(PatternError::Path {
                pattern: name,
                error,
            });
        }
        None if grid_pattern(pattern).is_none() => {
            return Err(PatternError::PathActuator { pattern: name });
        }
        None => None,
    };
    let pattern = *pattern;
    let settings = *settings;
    let mut index = 0usize;
    let mut path_started = false;
    Ok(core::iter::from_fn(move || match path.as_mut() {
        Some(cursor) => {
            if path_started && !cursor.advance() {
                return None;
            }
            path_started = true;
            Some(cursor.target())
        }
        None => {
            let target = grid_target(&pattern, index, &settings)?;
            index += 1;
            Some(target)
        }
    }))
}

/// Why a pattern (or goto) cannot run with the current settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PatternError {
    /// The path cannot be interpolated (radius below one step, too many
    /// steps, non-finite input).
    Path {
        /// Pattern name.
        pattern: &'static str,
        /// Why.
        error: kc::Error,
    },
    /// A point cannot be aimed at.
    Unreachable {
        /// Pattern name (`goto` for a single target).
        pattern: &'static str,
        /// Index of the first bad point.
        index: usize,
        /// The point, cm.
        point: PointCm,
        /// Why.
        error: kc::Error,
    },
    /// The pattern has no point on the configured grid.
    Empty {
        /// Pattern name.
        pattern: &'static str,
    },
    /// A point of the ideal figure between its interpolated points cannot
    /// be aimed at.
    FigureUnreachable {
        /// Pattern name.
        pattern: &'static str,
        /// The point, cm.
        point: PointCm,
        /// Why.
        error: kc::Error,
    },
    /// A point is outside the galvo's DAC range.
    OutsideGalvoRange {
        /// Pattern name (`goto` for a single target).
        pattern: &'static str,
        /// Index of the first bad point.
        index: usize,
        /// The point, cm.
        point: PointCm,
    },
    /// A path cannot be drawn by the selected actuator(s): paths run on
    /// one actuator at a time, and the tuning figure only on the galvo.
    PathActuator {
        /// Pattern name.
        pattern: &'static str,
    },
}

impl core::fmt::Display for PatternError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            PatternError::Path { pattern, error } => write!(f, "{pattern}: {error}"),
            PatternError::Unreachable {
                pattern,
                index,
                point,
                error,
            } => write!(
                f,
                "{pattern} point {index} ({}, {}) cm unreachable: {error}",
                Fixed::<2>(point.x_cm),
                Fixed::<2>(point.y_cm)
            ),
            PatternError::FigureUnreachable {
                pattern,
                point,
                error,
            } => write!(
                f,
                "{pattern} passes ({}, {}) cm, unreachable: {error}",
                Fixed::<2>(point.x_cm),
                Fixed::<2>(point.y_cm)
            ),
            PatternError::Empty { pattern } => write!(f, "{pattern} has no points on this grid"),
            PatternError::OutsideGalvoRange {
                pattern,
                index,
                point,
            } => write!(
                f,
                "{pattern} point {index} ({}, {}) cm is outside the galvo's range",
                Fixed::<2>(point.x_cm),
                Fixed::<2>(point.y_cm)
            ),
            PatternError::PathActuator { pattern } => write!(
                f,
                "{pattern}: paths run on one actuator at a time (tuning: galvo only); use target gimbal or galvo"
            ),
        }
    }
}

/// Whether the galvo can reach board point `point` (cm) within its DAC
/// range.
pub fn galvo_in_range(settings: &Settings, point: PointCm) -> bool {
    let galvo = super::galvo::config_from(&settings.galvo)
        .galvo
        .cast::<f64>();
    galvo
        .board_to_codes(kc::PointMm {
            x_mm: point.x_cm * 10.0,
            y_mm: point.y_cm * 10.0,
        })
        .is_ok_and(|codes| !codes.clamped())
}

/// Most points checked before a pattern starts (see [`PatternCheck`]).
pub const MAX_PROBES: usize = 16;

/// A point checked before a pattern starts.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Probe {
    /// Index within the pass when the probe is a point of the pass; `None`
    /// for a point of the ideal figure between interpolated points.
    index: Option<usize>,
    /// The point, cm.
    point: PointCm,
}

/// Checks one probe for every actuator that draws it.
fn check_probe(
    aimer: &Aimer,
    settings: &Settings,
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
    if actuator.uses_galvo() && !galvo_in_range(settings, point) {
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
    settings: &Settings,
    model: AimModel,
    actuator: Actuator,
    target: &Target,
) -> Result<(), PatternError> {
    let probe = Probe {
        index: Some(0),
        point: target.point,
    };
    check_probe(
        &Aimer::new(settings, model),
        settings,
        actuator,
        "goto",
        probe,
    )
}

/// `n` points of the ideal figure of a path pattern with more points than
/// [`MAX_PROBES`]: its start, ends, corners and extremes, and points spread
/// evenly between them.
fn figure_probes(pattern: &Pattern) -> heapless::Vec<Probe, MAX_PROBES> {
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
    match *pattern {
        Pattern::Line { from, to } => {
            let last = (MAX_PROBES - 1) as f64;
            for k in 0..MAX_PROBES {
                let (x, y) = lerp(from, to, k as f64 / last);
                push(x, y);
            }
        }
        Pattern::Circle {
            centre, radius_cm, ..
        } => {
            // From the top (the start), every 22.5°: the four extremes too.
            for k in 0..MAX_PROBES {
                let angle = core::f64::consts::FRAC_PI_2
                    + core::f64::consts::TAU * k as f64 / MAX_PROBES as f64;
                let (sin, cos) = libm::sincos(angle);
                push(centre.x_cm + radius_cm * cos, centre.y_cm + radius_cm * sin);
            }
        }
        Pattern::Rect { a, b } => {
            let corners = [
                a,
                PointCm {
                    x_cm: b.x_cm,
                    y_cm: a.y_cm,
                },
                b,
                PointCm {
                    x_cm: a.x_cm,
                    y_cm: b.y_cm,
                },
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
        Pattern::Grid(_) | Pattern::Tuning { .. } => {}
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
    pub fn new(
        pattern: &Pattern,
        settings: &Settings,
        actuator: Actuator,
    ) -> Result<Self, PatternError> {
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
            // The galvo marks the path itself: its corners must be in range.
            let path = galvo_path(pattern).ok_or(PatternError::Empty { pattern: name })?;
            for (index, [x_mm, y_mm]) in path.bounds_mm().into_iter().enumerate() {
                let point = PointCm {
                    x_cm: x_mm / 10.0,
                    y_cm: y_mm / 10.0,
                };
                if !galvo_in_range(settings, point) {
                    return Err(PatternError::OutsideGalvoRange {
                        pattern: name,
                        index,
                        point,
                    });
                }
            }
            return Ok(check);
        }
        let mut points = pass_points(pattern, settings)?;
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
        check.probes = match grid_pattern(pattern) {
            Some(grid_pattern) => {
                // Evenly spaced grid points, the first and the last among them.
                let last = grid_pattern
                    .indices(&grid(settings))
                    .len()
                    .saturating_sub(1);
                (0..MAX_PROBES)
                    .filter_map(|k| {
                        let index = k * last / (MAX_PROBES - 1);
                        let target = grid_target(pattern, index, settings)?;
                        Some(Probe {
                            index: Some(index),
                            point: target.point,
                        })
                    })
                    .collect()
            }
            None => figure_probes(pattern),
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
        settings: &Settings,
        model: AimModel,
        actuator: Actuator,
        max_points: usize,
    ) -> Result<bool, PatternError> {
        let aimer = Aimer::new(settings, model);
        let end = self.next.saturating_add(max_points).min(self.probes.len());
        while self.next < end {
            let probe = self.probes[self.next];
            check_probe(&aimer, settings, actuator, self.pattern, probe)?;
            self.next += 1;
        }
        Ok(self.next >= self.probes.len())
    }
}

/// Checks before a pattern starts that it has points and that it is
/// reachable at its probe points (see [`PatternCheck`]), all at once; the
/// error names the first bad point.
pub fn check_pattern(
    pattern: &Pattern,
    settings: &Settings,
    model: AimModel,
    actuator: Actuator,
) -> Result<(), PatternError> {
    let mut check = PatternCheck::new(pattern, settings, actuator)?;
    check
        .step(settings, model, actuator, usize::MAX)
        .map(|_| ())
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;

    fn exact_fk(settings: &Settings, aim: &Aim) -> BoardPoint {
        gimbal(settings, AimModel::Exact)
            .fk_wire(kc::WireAngles {
                yaw: aim.yaw_wire,
                pitch: aim.pitch_wire,
            })
            .unwrap()
    }

    #[test]
    fn aim_lands_on_the_target_within_wire_resolution() {
        let s = Settings::default();
        for (x, y) in [(0.0, 0.0), (10.0, 5.0), (-11.5, -7.66), (11.5, 7.66)] {
            let a = aim(&s, AimModel::Exact, PointCm { x_cm: x, y_cm: y }).unwrap();
            let p = exact_fk(&s, &a);
            // 0.05° of wire rounding at ~30 cm is < 0.5 mm.
            assert!(
                (p.x_cm - x).abs() < 0.05 && (p.y_cm - y).abs() < 0.05,
                "{p:?}"
            );
        }
    }

    #[test]
    fn aim_applies_direction_zero_and_error_model() {
        let base = Settings::default();
        let p = PointCm {
            x_cm: 8.0,
            y_cm: 3.0,
        };
        let plain = aim(&base, AimModel::Exact, p).unwrap();
        let mut turned = base;
        turned.yaw.direction = -1;
        turned.yaw.zero_deg = 10.0;
        let t = aim(&turned, AimModel::Exact, p).unwrap();
        assert_eq!(t.yaw_deg, plain.yaw_deg);
        assert!((f64::from(t.yaw_wire) - (100.0 - f64::from(plain.yaw_wire))).abs() <= 1.0);
        // A constant +2 mm x error is pre-compensated by aiming 2 mm left.
        let mut biased = base;
        biased.err_dx[0] = 2.0;
        let b = aim(&biased, AimModel::Exact, p).unwrap();
        let q = exact_fk(&base, &b);
        assert!((q.x_cm - (p.x_cm - 0.2)).abs() < 0.05, "{q:?}");
    }

    #[test]
    fn unreachable_targets_are_errors_not_nan() {
        let s = Settings::default();
        for p in [
            PointCm {
                x_cm: f64::NAN,
                y_cm: 0.0,
            },
            PointCm {
                x_cm: f64::INFINITY,
                y_cm: 0.0,
            },
        ] {
            assert!(aim(&s, AimModel::Exact, p).is_err(), "{p:?}");
        }
        let mut limited = s;
        limited.pitch.max_deg = 30.0;
        let far_down = PointCm {
            x_cm: 0.0,
            y_cm: -100.0,
        };
        assert!(aim(&s, AimModel::Exact, far_down).is_ok());
        assert!(aim(&limited, AimModel::Exact, far_down).is_err());
        assert!(grid_point(&s, 7, 0).is_err());
        assert_eq!(grid_point(&s, -6, 4).unwrap().point.x_cm, -6.0 * 1.916);
    }

    #[test]
    fn patterns_yield_their_points_in_order_and_end() {
        let s = Settings::default();
        let corner: heapless::Vec<(i8, i8), 8> =
            pass_points(&Pattern::Grid(kc::Pattern::Corner), &s)
                .unwrap()
                .filter_map(|t| t.grid)
                .collect();
        assert_eq!(corner.as_slice(), &[(-6, 4), (6, 4), (6, -4), (-6, -4)]);
        let n = pass_points(&Pattern::Grid(kc::Pattern::FullSerpentine), &s)
            .unwrap()
            .count();
        assert_eq!(n, 13 * 9);
        let line = Pattern::Line {
            from: PointCm {
                x_cm: 0.0,
                y_cm: 0.0,
            },
            to: PointCm {
                x_cm: 2.0,
                y_cm: 1.0,
            },
        };
        let last = pass_points(&line, &s).unwrap().last().unwrap();
        assert_eq!(
            last.point,
            PointCm {
                x_cm: 2.0,
                y_cm: 1.0
            }
        );
        assert!(check_pattern(&line, &s, AimModel::Exact, Actuator::Gimbal).is_ok());
    }

    #[test]
    fn check_pattern_names_the_first_unreachable_point() {
        let mut s = Settings::default();
        s.yaw.min_deg = -10.0;
        let e = check_pattern(
            &Pattern::Grid(kc::Pattern::Corner),
            &s,
            AimModel::Exact,
            Actuator::Gimbal,
        )
        .unwrap_err();
        let text = std::format!("{e}");
        assert!(
            text.starts_with("corner point 1 (11.50, 7.66) cm unreachable"),
            "{text}"
        );
        let tiny = Pattern::Circle {
            centre: PointCm {
                x_cm: 0.0,
                y_cm: 0.0,
            },
            radius_cm: 0.01,
            rotation: kc::Rotation::Cw,
        };
        assert!(
            check_pattern(
                &tiny,
                &Settings::default(),
                AimModel::Exact,
                Actuator::Gimbal
            )
            .is_err()
        );
    }

    fn line(x0: f64, y0: f64, x1: f64, y1: f64) -> Pattern {
        Pattern::Line {
            from: PointCm { x_cm: x0, y_cm: y0 },
            to: PointCm { x_cm: x1, y_cm: y1 },
        }
    }

    #[test]
    fn a_path_cursor_steps_through_the_interpolated_points() {
        let s = Settings {
            path_step_cm: 0.3,
            ..Settings::default()
        };
        let circle = Pattern::Circle {
            centre: PointCm {
                x_cm: 1.0,
                y_cm: -2.0,
            },
            radius_cm: 4.0,
            rotation: kc::Rotation::Ccw,
        };
        let rect = Pattern::Rect {
            a: PointCm {
                x_cm: -3.0,
                y_cm: 2.0,
            },
            b: PointCm {
                x_cm: 4.5,
                y_cm: -1.2,
            },
        };
        for pattern in [line(-5.0, 1.0, 7.3, -2.2), circle, rect] {
            let expect: std::vec::Vec<BoardPoint> = match path_points(&pattern, &s) {
                Some(Ok(PathPoints::Line(p))) => p.collect(),
                Some(Ok(PathPoints::Arc(p))) => p.collect(),
                Some(Ok(PathPoints::Rect(p))) => p.collect(),
                _ => panic!("{pattern:?} is a path"),
            };
            let mut cursor = PathCursor::start(&pattern, &s).unwrap().unwrap();
            let mut got = std::vec![cursor.target().point];
            while cursor.advance() {
                got.push(cursor.target().point);
            }
            let expect: std::vec::Vec<PointCm> = expect.into_iter().map(point_cm).collect();
            assert_eq!(got, expect, "{pattern:?}");
            // At the end it stays on the last point.
            assert!(!cursor.advance());
            assert_eq!(Some(&cursor.target().point), expect.last());
        }
        assert!(PathCursor::start(&Pattern::Grid(kc::Pattern::Corner), &s).is_none());
    }

    #[test]
    fn a_long_path_is_checked_at_a_bounded_number_of_points() {
        let s = Settings {
            path_step_cm: 0.01,
            ..Settings::default()
        };
        // 40 000 interpolated points.
        let long = line(-200.0, 0.0, 200.0, 0.0);
        let mut check = PatternCheck::new(&long, &s, Actuator::Gimbal).unwrap();
        let mut steps = 0;
        while !check
            .step(&s, AimModel::Exact, Actuator::Gimbal, 4)
            .unwrap()
        {
            steps += 1;
        }
        assert_eq!(steps, MAX_PROBES / 4 - 1, "16 probes, 4 per step");
        // The probes span the whole figure: an end out of reach is found.
        let mut limited = s;
        limited.yaw.max_deg = 60.0;
        limited.yaw.min_deg = -60.0;
        let e = check_pattern(&long, &limited, AimModel::Exact, Actuator::Gimbal).unwrap_err();
        let text = std::format!("{e}");
        assert!(
            text.starts_with("line passes (-200.00, 0.00) cm, unreachable"),
            "{text}"
        );
        // A short path is checked at every point; the error names it.
        let mut short = Settings::default();
        short.yaw.min_deg = -20.0;
        short.yaw.max_deg = 20.0;
        let e = check_pattern(
            &line(0.0, 0.0, 20.0, 0.0),
            &short,
            AimModel::Exact,
            Actuator::Gimbal,
        )
        .unwrap_err();
        assert!(
            matches!(e, PatternError::FigureUnreachable { .. }),
            "100 points at 0.2 cm are probed: {e}"
        );
        let e = check_pattern(
            &line(8.0, 0.0, 10.0, 0.0),
            &short,
            AimModel::Exact,
            Actuator::Gimbal,
        )
        .unwrap_err();
        assert!(
            matches!(e, PatternError::Unreachable { index, .. } if index > 0),
            "11 points are each checked: {e}"
        );
    }

    #[test]
    fn figure_probes_cover_ends_corners_and_extremes() {
        let has = |probes: &[Probe], x: f64, y: f64| {
            probes
                .iter()
                .any(|p| (p.point.x_cm - x).abs() < 1e-9 && (p.point.y_cm - y).abs() < 1e-9)
        };
        let l = figure_probes(&line(-3.0, 1.0, 5.0, -7.0));
        assert!(has(&l, -3.0, 1.0) && has(&l, 5.0, -7.0));
        let c = figure_probes(&Pattern::Circle {
            centre: PointCm {
                x_cm: 1.0,
                y_cm: 2.0,
            },
            radius_cm: 3.0,
            rotation: kc::Rotation::Cw,
        });
        for (x, y) in [(1.0, 5.0), (4.0, 2.0), (1.0, -1.0), (-2.0, 2.0)] {
            assert!(has(&c, x, y), "({x}, {y}) in {c:?}");
        }
        let r = figure_probes(&Pattern::Rect {
            a: PointCm {
                x_cm: -1.0,
                y_cm: 2.0,
            },
            b: PointCm {
                x_cm: 3.0,
                y_cm: -4.0,
            },
        });
        for (x, y) in [(-1.0, 2.0), (3.0, 2.0), (3.0, -4.0), (-1.0, -4.0)] {
            assert!(has(&r, x, y), "({x}, {y}) in {r:?}");
        }
        for probes in [&l, &c, &r] {
            assert_eq!(probes.len(), MAX_PROBES);
        }
    }
}
