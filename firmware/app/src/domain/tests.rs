//! Tests of the domain layer: aiming, pattern points, path cursors and
//! pattern checks, with the geometry the default settings describe.

extern crate std;

use kinematics_core as kc;
use kinematics_core::{BoardPoint, RectSteps};

use super::check::{Probe, figure_probes};
use super::*;
use crate::settings::Settings;

fn aim(settings: &Settings, model: AimModel, point: PointCm) -> Result<Aim, kc::Error> {
    settings.aimer(model).aim(point)
}

fn exact(settings: &Settings) -> Aimer {
    settings.aimer(AimModel::Exact)
}

fn exact_fk(settings: &Settings, aim: &Aim) -> BoardPoint {
    settings
        .gimbal(AimModel::Exact)
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
    assert!(exact(&s).grid_point(7, 0).is_err());
    assert_eq!(
        exact(&s).grid_point(-6, 4).unwrap().point.x_cm,
        -6.0 * 1.916
    );
}

#[test]
fn patterns_yield_their_points_in_order_and_end() {
    let s = Settings::default();
    let corner: heapless::Vec<(i8, i8), 8> =
        pass_points(&Pattern::Grid(kc::Pattern::Corner), &exact(&s))
            .unwrap()
            .filter_map(|t| t.grid)
            .collect();
    assert_eq!(corner.as_slice(), &[(-6, 4), (6, 4), (6, -4), (-6, -4)]);
    let n = pass_points(&Pattern::Grid(kc::Pattern::FullSerpentine), &exact(&s))
        .unwrap()
        .count();
    assert_eq!(n, 13 * 9);
    let line = Pattern::Path(Figure::Line {
        from: PointCm {
            x_cm: 0.0,
            y_cm: 0.0,
        },
        to: PointCm {
            x_cm: 2.0,
            y_cm: 1.0,
        },
    });
    let last = pass_points(&line, &exact(&s)).unwrap().last().unwrap();
    assert_eq!(
        last.point,
        PointCm {
            x_cm: 2.0,
            y_cm: 1.0
        }
    );
    assert!(check_pattern(&line, &exact(&s), Actuator::Gimbal).is_ok());
}

#[test]
fn check_pattern_names_the_first_unreachable_point() {
    let mut s = Settings::default();
    s.yaw.min_deg = -10.0;
    let e = check_pattern(
        &Pattern::Grid(kc::Pattern::Corner),
        &exact(&s),
        Actuator::Gimbal,
    )
    .unwrap_err();
    let text = std::format!("{e}");
    assert!(
        text.starts_with("corner point 1 (11.50, 7.66) cm unreachable"),
        "{text}"
    );
    let tiny = Pattern::Path(Figure::Circle {
        centre: PointCm {
            x_cm: 0.0,
            y_cm: 0.0,
        },
        radius_cm: 0.01,
        rotation: kc::Rotation::Cw,
    });
    assert!(check_pattern(&tiny, &exact(&Settings::default()), Actuator::Gimbal).is_err());
}

fn line_figure(x0: f64, y0: f64, x1: f64, y1: f64) -> Figure {
    Figure::Line {
        from: PointCm { x_cm: x0, y_cm: y0 },
        to: PointCm { x_cm: x1, y_cm: y1 },
    }
}

fn line(x0: f64, y0: f64, x1: f64, y1: f64) -> Pattern {
    Pattern::Path(line_figure(x0, y0, x1, y1))
}

#[test]
fn a_path_cursor_steps_through_the_interpolated_points() {
    let s = Settings {
        path_step_cm: 0.3,
        ..Settings::default()
    };
    let circle = Pattern::Path(Figure::Circle {
        centre: PointCm {
            x_cm: 1.0,
            y_cm: -2.0,
        },
        radius_cm: 4.0,
        rotation: kc::Rotation::Ccw,
    });
    let rect = Pattern::Path(Figure::Rect {
        a: PointCm {
            x_cm: -3.0,
            y_cm: 2.0,
        },
        b: PointCm {
            x_cm: 4.5,
            y_cm: -1.2,
        },
    });
    for pattern in [line(-5.0, 1.0, 7.3, -2.2), circle, rect] {
        // The cursor yields what the geometry's interpolator of the
        // figure yields.
        let (step, criterion) = (s.path_step_cm, kc::Criterion::Midpoint);
        let expect: std::vec::Vec<BoardPoint> = match pattern {
            Pattern::Path(Figure::Line { from, to }) => {
                kc::LineSteps::new(from.board(), to.board(), step, criterion)
                    .unwrap()
                    .collect()
            }
            Pattern::Path(Figure::Circle {
                centre,
                radius_cm,
                rotation,
            }) => kc::ArcSteps::circle(centre.board(), radius_cm, rotation, step, criterion)
                .unwrap()
                .collect(),
            Pattern::Path(Figure::Rect { a, b }) => {
                RectSteps::new(a.board(), b.board(), step, criterion)
                    .unwrap()
                    .collect()
            }
            _ => panic!("{pattern:?} is a path"),
        };
        let mut cursor = PathCursor::start(&pattern, &exact(&s)).unwrap().unwrap();
        let mut got = std::vec![cursor.target().point];
        while cursor.advance() {
            got.push(cursor.target().point);
        }
        let expect: std::vec::Vec<PointCm> = expect.into_iter().map(PointCm::from_board).collect();
        assert_eq!(got, expect, "{pattern:?}");
        // At the end it stays on the last point.
        assert!(!cursor.advance());
        assert_eq!(Some(&cursor.target().point), expect.last());
    }
    assert!(PathCursor::start(&Pattern::Grid(kc::Pattern::Corner), &exact(&s)).is_none());
}

#[test]
fn a_long_path_is_checked_at_a_bounded_number_of_points() {
    let s = Settings {
        path_step_cm: 0.01,
        ..Settings::default()
    };
    // 40 000 interpolated points.
    let long = line(-200.0, 0.0, 200.0, 0.0);
    let aimer = exact(&s);
    let mut check = PatternCheck::new(&long, &aimer, Actuator::Gimbal).unwrap();
    let mut steps = 0;
    while !check.step(&aimer, Actuator::Gimbal, 4).unwrap() {
        steps += 1;
    }
    assert_eq!(steps, MAX_PROBES / 4 - 1, "16 probes, 4 per step");
    // The probes span the whole figure: an end out of reach is found.
    let mut limited = s;
    limited.yaw.max_deg = 60.0;
    limited.yaw.min_deg = -60.0;
    let e = check_pattern(&long, &exact(&limited), Actuator::Gimbal).unwrap_err();
    let text = std::format!("{e}");
    assert!(
        text.starts_with("line passes (-200.00, 0.00) cm, unreachable"),
        "{text}"
    );
    // A short path is checked at every point; the error names it.
    let mut short = Settings::default();
    short.yaw.min_deg = -20.0;
    short.yaw.max_deg = 20.0;
    let e =
        check_pattern(&line(0.0, 0.0, 20.0, 0.0), &exact(&short), Actuator::Gimbal).unwrap_err();
    assert!(
        matches!(e, PatternError::FigureUnreachable { .. }),
        "100 points at 0.2 cm are probed: {e}"
    );
    let e =
        check_pattern(&line(8.0, 0.0, 10.0, 0.0), &exact(&short), Actuator::Gimbal).unwrap_err();
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
    let l = figure_probes(&line_figure(-3.0, 1.0, 5.0, -7.0));
    assert!(has(&l, -3.0, 1.0) && has(&l, 5.0, -7.0));
    let c = figure_probes(&Figure::Circle {
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
    let r = figure_probes(&Figure::Rect {
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
