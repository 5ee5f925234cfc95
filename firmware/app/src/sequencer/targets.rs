//! From commands to servo angles: the points of each pattern and path, and
//! the aiming chain board point → error-model compensation → gimbal IK
//! (exact or seed) → servo mapping → FashionStar wire value. All geometry
//! is `kinematics-core`; this module only builds its inputs from
//! [`Settings`].

use kinematics_core as kc;
use kinematics_core::{BoardPoint, Criterion, ErrorModel, Gimbal, Grid, GridIndex};

use crate::cli::format::Fixed;
use crate::command::{Actuator, AimModel, Pattern, PointCm};
use crate::galvo::GalvoPath;
use crate::settings::{AxisSettings, Settings};

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

/// Servo angles that put the spot on board point `point` (cm): the error
/// model pre-compensates the point, the gimbal IK of `model` gives the
/// joint angles, the servo mapping the wire values (limits checked).
///
/// Errors: unreachable or non-finite targets, servo limits, a diverging
/// error model — never NaN angles.
pub fn aim(settings: &Settings, model: AimModel, point: PointCm) -> Result<Aim, kc::Error> {
    let corrected = error_model(settings).compensate_board(board(point))?;
    let gimbal = gimbal(settings, model);
    let joints = gimbal.ik(corrected)?;
    let wire = gimbal.to_wire(joints)?;
    Ok(Aim {
        yaw_deg: joints.yaw_deg,
        pitch_deg: joints.pitch_deg,
        yaw_wire: wire.yaw,
        pitch_wire: wire.pitch,
    })
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

    fn nth(&mut self, n: usize) -> Option<BoardPoint> {
        match self {
            PathPoints::Line(steps) => steps.nth(n),
            PathPoints::Arc(steps) => steps.nth(n),
            PathPoints::Rect(steps) => steps.nth(n),
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

/// Point `index` (from 0) of one pass of `pattern`; `None` past the end
/// of the pass (or when the pattern cannot be built with `settings`).
pub fn pattern_target(pattern: &Pattern, index: usize, settings: &Settings) -> Option<Target> {
    if let Some(grid_pattern) = grid_pattern(pattern) {
        let grid = grid(settings);
        let idx = grid_pattern.indices(&grid).nth(index)?;
        let point = grid.point(idx).ok()?;
        return Some(Target {
            point: point_cm(point),
            grid: Some((idx.xi, idx.yi)),
        });
    }
    let point = path_points(pattern, settings)?.ok()?.nth(index)?;
    Some(Target {
        point: point_cm(point),
        grid: None,
    })
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
    let galvo = crate::galvo::config_from(&settings.galvo)
        .galvo
        .cast::<f64>();
    galvo
        .board_to_codes(kc::PointMm {
            x_mm: point.x_cm * 10.0,
            y_mm: point.y_cm * 10.0,
        })
        .is_ok_and(|codes| !codes.clamped())
}

/// Checks point `index` of `pattern` for every actuator that draws it.
fn check_point(
    settings: &Settings,
    model: AimModel,
    actuator: Actuator,
    pattern: &'static str,
    index: usize,
    point: PointCm,
) -> Result<(), PatternError> {
    if actuator.uses_gimbal() {
        aim(settings, model, point).map_err(|error| PatternError::Unreachable {
            pattern,
            index,
            point,
            error,
        })?;
    }
    if actuator.uses_galvo() && !galvo_in_range(settings, point) {
        return Err(PatternError::OutsideGalvoRange {
            pattern,
            index,
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
    check_point(settings, model, actuator, "goto", 0, target.point)
}

/// Checks before a pattern starts that it has points and that every one
/// of them is reachable; the error names the first bad point.
pub fn check_pattern(
    pattern: &Pattern,
    settings: &Settings,
    model: AimModel,
    actuator: Actuator,
) -> Result<(), PatternError> {
    let name = pattern.name();
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
        return Ok(());
    }
    if matches!(pattern, Pattern::Tuning { .. }) {
        return Err(PatternError::PathActuator { pattern: name });
    }
    if let Some(Err(error)) = path_points(pattern, settings) {
        return Err(PatternError::Path {
            pattern: name,
            error,
        });
    }
    let mut count = 0usize;
    while let Some(target) = pattern_target(pattern, count, settings) {
        check_point(settings, model, actuator, name, count, target.point)?;
        count += 1;
    }
    if count == 0 {
        return Err(PatternError::Empty { pattern: name });
    }
    Ok(())
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
        let corner: heapless::Vec<(i8, i8), 8> = (0..)
            .map_while(|i| pattern_target(&Pattern::Grid(kc::Pattern::Corner), i, &s))
            .filter_map(|t| t.grid)
            .collect();
        assert_eq!(corner.as_slice(), &[(-6, 4), (6, 4), (6, -4), (-6, -4)]);
        let n = (0..)
            .map_while(|i| pattern_target(&Pattern::Grid(kc::Pattern::FullSerpentine), i, &s))
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
        let last = (0..)
            .map_while(|i| pattern_target(&line, i, &s))
            .last()
            .unwrap();
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
}
