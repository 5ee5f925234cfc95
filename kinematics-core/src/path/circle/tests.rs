extern crate std;
use super::*;
use crate::path::test_support::cheb_to_circle;
use proptest::prelude::*;
use std::vec::Vec;

/// The seed's `drawcircle` loop transcribed literally (Step_one = 1),
/// with the start point prepended.
fn seed_drawcircle(x0: f64, y0: f64, r: f64, sorn: u8) -> Vec<(f64, f64)> {
    let (xe, ye) = (x0, y0 + r);
    let (mut xm, mut ym) = (x0, y0 + r);
    let (mut step, mut fm) = (0, 0.0);
    let mut out = std::vec![(xm, ym)];
    while (xm - xe) * (xm - xe) + (ym - ye) * (ym - ye) > 0.5 || step == 0 {
        let q = if xm - x0 > 0.0 && ym - y0 >= 0.0 {
            1
        } else if xm - x0 <= 0.0 && ym - y0 > 0.0 {
            2
        } else if xm - x0 < 0.0 && ym - y0 <= 0.0 {
            3
        } else {
            4
        };
        match (q, sorn) {
            (1, 1) => {
                if fm >= 0.0 {
                    ym -= 1.0
                } else {
                    xm += 1.0
                }
            }
            (1, _) => {
                if fm <= 0.0 {
                    ym += 1.0
                } else {
                    xm -= 1.0
                }
            }
            (2, 1) => {
                if fm >= 0.0 {
                    xm += 1.0
                } else {
                    ym += 1.0
                }
            }
            (2, _) => {
                if fm > 0.0 {
                    ym -= 1.0
                } else {
                    xm -= 1.0
                }
            }
            (3, 1) => {
                if fm >= 0.0 {
                    ym += 1.0
                } else {
                    xm -= 1.0
                }
            }
            (3, _) => {
                if fm > 0.0 {
                    xm += 1.0
                } else {
                    ym -= 1.0
                }
            }
            (_, 1) => {
                if fm >= 0.0 {
                    xm -= 1.0
                } else {
                    ym -= 1.0
                }
            }
            (_, _) => {
                if fm > 0.0 {
                    ym += 1.0
                } else {
                    xm += 1.0
                }
            }
        }
        step += 1;
        fm = (xm - x0) * (xm - x0) + (ym - y0) * (ym - y0) - r * r;
        out.push((xm, ym));
        assert!(step < 100_000, "seed loop did not stop");
    }
    out
}

fn walk(it: ArcSteps) -> Vec<(f64, f64)> {
    it.map(|p| (p.x_cm, p.y_cm)).collect()
}

#[test]
fn seed_criterion_reproduces_the_seed_circle() {
    for r in [1.0, 2.0, 3.0, 5.0, 8.0, 13.0, 25.0] {
        for (rot, sorn) in [(Rotation::Cw, 1), (Rotation::Ccw, 2)] {
            let c = BoardPoint::new(3.0, -2.0);
            let ours = walk(ArcSteps::circle(c, r, rot, 1.0, Criterion::Seed).unwrap());
            let seed = seed_drawcircle(3.0, -2.0, r, sorn);
            assert_eq!(ours, seed, "r {r} {rot:?}");
        }
    }
}

#[test]
fn radius_two_midpoint_circle_by_hand() {
    // Clockwise from the top (0, 2), centre (0, 0), unit steps, F at the
    // midpoint of the two candidates.
    let c = BoardPoint::new(0.0, 0.0);
    let v = walk(ArcSteps::circle(c, 2.0, Rotation::Cw, 1.0, Criterion::Midpoint).unwrap());
    let expect = [
        (0.0, 2.0),
        (1.0, 2.0),  // Q2: mid (½, 2½) outside → inward +x
        (1.0, 1.0),  // Q1: mid (1½, 1½): 4.5 > 4 → inward −y
        (2.0, 1.0),  // Q1: mid (1½, ½): 2.5 < 4 → outward +x
        (2.0, 0.0),  // Q1: mid (2½, ½) outside → inward −y
        (2.0, -1.0), // Q1 (y = 0): mid (2½, −½) outside → −y
        (1.0, -1.0), // Q4: mid (1½, −1½) outside → inward −x
        (1.0, -2.0), // Q4: mid (½, −1½): 2.5 < 4 → outward −y
        (0.0, -2.0),
        (-1.0, -2.0),
        (-1.0, -1.0),
        (-2.0, -1.0),
        (-2.0, 0.0),
        (-2.0, 1.0),
        (-1.0, 1.0),
        (-1.0, 2.0),
        (0.0, 2.0),
    ];
    assert_eq!(v, expect);
}

#[test]
fn quarter_arcs_end_exactly_both_directions() {
    let c = BoardPoint::new(1.0, 1.0);
    let a = BoardPoint::new(6.0, 1.0);
    let b = BoardPoint::new(1.0, 6.0);
    let ccw = walk(ArcSteps::arc(a, b, c, Rotation::Ccw, 1.0, Criterion::Midpoint).unwrap());
    assert_eq!(ccw.first(), Some(&(6.0, 1.0)));
    assert_eq!(ccw.last(), Some(&(1.0, 6.0)));
    // A quarter of radius 5: 5 moves on each axis.
    assert_eq!(ccw.len(), 11);
    // The same end points clockwise go the long way round: 3 quarters.
    let cw = walk(ArcSteps::arc(a, b, c, Rotation::Cw, 1.0, Criterion::Midpoint).unwrap());
    assert_eq!(cw.last(), Some(&(1.0, 6.0)));
    assert_eq!(cw.len(), 31);
}

#[test]
fn invalid_arcs_are_errors() {
    let c = BoardPoint::new(0.0, 0.0);
    let m = Criterion::Midpoint;
    assert_eq!(
        ArcSteps::circle(c, 0.5, Rotation::Cw, 1.0, m).err(),
        Some(Error::PathTooShort)
    );
    assert_eq!(
        ArcSteps::arc(
            BoardPoint::new(5.0, 0.0),
            BoardPoint::new(0.0, 6.0),
            c,
            Rotation::Ccw,
            1.0,
            m
        )
        .err(),
        Some(Error::EndNotOnCircle)
    );
    assert_eq!(
        ArcSteps::circle(c, f64::NAN, Rotation::Cw, 1.0, m).err(),
        Some(Error::NonFinite { what: "radius_cm" })
    );
    assert_eq!(
        ArcSteps::circle(c, 1e9, Rotation::Cw, 1e-3, m).err(),
        Some(Error::TooManySteps)
    );
    assert!(matches!(
        ArcSteps::circle(c, 5.0, Rotation::Cw, -1.0, m),
        Err(Error::InvalidConfig { .. })
    ));
    assert_eq!(
        ArcSteps::circle(c, 1e300, Rotation::Cw, 1e-300, m).err(),
        Some(Error::TooManySteps)
    );
}

/// Checks the walk: starts on `a`, ends exactly on `b`, unit moves on
/// one axis between lattice points, every point within `bound` steps
/// (Chebyshev) of the circle, and a bounded final connection.
fn check_arc(
    a: BoardPoint,
    b: BoardPoint,
    c: BoardPoint,
    rot: Rotation,
    step: f64,
    crit: Criterion,
    bound: f64,
) -> Result<usize, TestCaseError> {
    let v: Vec<_> = ArcSteps::arc(a, b, c, rot, step, crit).unwrap().collect();
    let r = libm::hypot(a.x_cm - c.x_cm, a.y_cm - c.y_cm);
    prop_assert_eq!(v[0], a);
    prop_assert_eq!(*v.last().unwrap(), b);
    prop_assert!(v.len() as f64 <= 8.0 * (r / step + 2.0) + 3.0);
    for p in &v {
        let d = cheb_to_circle(*p, c, r) / step;
        prop_assert!(d <= bound + 1e-9, "{:?} is {} steps off", p, d);
    }
    let n = v.len();
    // Lattice moves: all but the last move (which may join the end point).
    for w in v[..n.saturating_sub(1)].windows(2) {
        let (dx, dy) = ((w[1].x_cm - w[0].x_cm).abs(), (w[1].y_cm - w[0].y_cm).abs());
        let unit = |d: f64| (d - step).abs() < 1e-9 * step.max(1.0) * 1e3;
        prop_assert!(
            (unit(dx) && dy < 1e-9) || (unit(dy) && dx < 1e-9),
            "{:?}",
            w
        );
    }
    if n >= 2 {
        let (p, q) = (v[n - 2], v[n - 1]);
        let d = (p.x_cm - q.x_cm).abs().max((p.y_cm - q.y_cm).abs()) / step;
        prop_assert!(d <= 1.5 + 1e-9, "final join {} steps", d);
    }
    Ok(n)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1500))]

    #[test]
    fn full_circles_close_within_half_a_step(
        cx in -10.0f64..10.0, cy in -10.0f64..10.0, r in 1.0f64..60.0, step in 0.05f64..1.0, ccw: bool,
    ) {
        let r = r * step;
        let rot = if ccw { Rotation::Ccw } else { Rotation::Cw };
        let c = BoardPoint::new(cx, cy);
        let a = BoardPoint::new(cx, cy + r);
        let v: Vec<_> = ArcSteps::circle(c, r, rot, step, Criterion::Midpoint).unwrap().collect();
        prop_assert_eq!(*v.last().unwrap(), a);
        check_arc(a, a, c, rot, step, Criterion::Midpoint, 0.5)?;
        // Closes on the lattice: the last move is a unit move back to the start.
        let (p, q) = (v[v.len() - 2], v[v.len() - 1]);
        let (dx, dy) = ((p.x_cm - q.x_cm).abs(), (p.y_cm - q.y_cm).abs());
        prop_assert!((dx - step).abs() + dy < 1e-9 || (dy - step).abs() + dx < 1e-9, "{:?}", (p, q));
    }

    #[test]
    fn arcs_end_exactly_within_half_a_step(
        cx in -10.0f64..10.0, cy in -10.0f64..10.0, r in 1.0f64..60.0, step in 0.05f64..1.0,
        a0 in -PI..PI, a1 in -PI..PI, ccw: bool,
    ) {
        let r = r * step;
        let rot = if ccw { Rotation::Ccw } else { Rotation::Cw };
        let c = BoardPoint::new(cx, cy);
        let a = BoardPoint::new(cx + r * libm::cos(a0), cy + r * libm::sin(a0));
        let b = BoardPoint::new(cx + r * libm::cos(a1), cy + r * libm::sin(a1));
        check_arc(a, b, c, rot, step, Criterion::Midpoint, 0.5)?;
    }

    #[test]
    fn seed_circles_stay_within_one_step(
        cx in -10.0f64..10.0, cy in -10.0f64..10.0, r in 1.0f64..60.0, ccw: bool,
    ) {
        let rot = if ccw { Rotation::Ccw } else { Rotation::Cw };
        let c = BoardPoint::new(cx, cy);
        let a = BoardPoint::new(cx, cy + r);
        check_arc(a, a, c, rot, 1.0, Criterion::Seed, 1.0)?;
    }
}
