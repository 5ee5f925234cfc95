extern crate std;
use super::*;
use crate::grbl::block::{Laser, SpindleMode};
use crate::grbl::state::Units;
use core::f64::consts::PI;
use std::vec::Vec;

fn p(x_mm: f64, y_mm: f64) -> PointMm {
    PointMm { x_mm, y_mm }
}

fn run(state: &mut ParserState, line: &str) -> Vec<Block> {
    match state.execute(line) {
        Ok(blocks) => blocks.into_iter().collect(),
        Err(e) => panic!("{line:?}: error:{}", e.code()),
    }
}

fn error(state: &ParserState, line: &str) -> u8 {
    let mut copy = *state;
    let result = copy.execute(line);
    assert_eq!(copy, *state, "{line:?} changed the state");
    match result {
        Err(e) => e.code(),
        Ok(b) => panic!("{line:?} accepted: {b:?}"),
    }
}

fn near(a: PointMm, b: PointMm) -> bool {
    a.distance_to(b) < 1e-9
}

#[test]
fn rapid_and_feed_lines_in_board_mm() {
    let mut s = ParserState::new();
    assert_eq!(
        run(&mut s, "G0 X10 Y-5"),
        [Block::Rapid {
            from: p(0.0, 0.0),
            to: p(10.0, -5.0)
        }]
    );
    let laser = Laser {
        mode: SpindleMode::Constant,
        power: 500.0,
    };
    assert_eq!(
        run(&mut s, "M3 S500 G1 X20 F1200"),
        [Block::Line {
            from: p(10.0, -5.0),
            to: p(20.0, -5.0),
            feed_mm_min: 1200.0,
            laser
        }]
    );
    // Modal G1 and F; bare axis words move.
    assert_eq!(
        run(&mut s, "Y5"),
        [Block::Line {
            from: p(20.0, -5.0),
            to: p(20.0, 5.0),
            feed_mm_min: 1200.0,
            laser
        }]
    );
    // Zero-length moves and Z-only moves yield nothing.
    assert!(run(&mut s, "X20 Z3").is_empty());
    assert_eq!(s.position, p(20.0, 5.0));
}

#[test]
fn units_distance_and_offsets() {
    let mut s = ParserState::new();
    run(&mut s, "G20 G0 X1 Y2");
    assert!(near(s.position, p(25.4, 50.8)));
    run(&mut s, "G21 G91 G0 X1 Y-1");
    assert!(near(s.position, p(26.4, 49.8)));
    run(&mut s, "G90 G92 X0 Y0");
    assert!(near(s.work_offset(), p(26.4, 49.8)));
    run(&mut s, "G0 X1");
    assert!(near(s.position, p(27.4, 49.8)));
    run(&mut s, "G53 G0 X0 Y0");
    assert!(near(s.position, p(0.0, 0.0)));
    run(&mut s, "G92.1");
    assert_eq!(s.g92, PointMm::ZERO);
    // G10 L20 P1: the current position reads as the values.
    run(&mut s, "G0 X5 Y5");
    run(&mut s, "G10 L20 P1 X0 Y1");
    assert!(near(s.g54, p(5.0, 4.0)));
    run(&mut s, "G10 L2 P0 X-1");
    assert!(near(s.g54, p(-1.0, 4.0)));
    assert_eq!(s.position, p(5.0, 5.0), "offsets do not move");
}

#[test]
fn feed_units_and_inverse_time() {
    let mut s = ParserState::new();
    run(&mut s, "G20 G1 X1 F10");
    assert!((s.feed_mm_min - 254.0).abs() < 1e-9);
    run(&mut s, "G21 G0 X0");
    let blocks = run(&mut s, "G93 G1 X30 Y40 F2");
    match blocks[..] {
        // 50 mm in 1/2 min: 100 mm/min.
        [Block::Line { feed_mm_min, .. }] => assert!((feed_mm_min - 100.0).abs() < 1e-9),
        ref other => panic!("{other:?}"),
    }
    assert_eq!(error(&s, "G1 X0"), 22, "G93 needs F in every feed block");
    // Leaving G93 without F leaves the feed undefined.
    assert_eq!(error(&s, "G94 G1 X0"), 22);
    run(&mut s, "G94 G1 X0 F600");
    assert_eq!(s.feed_mm_min, 600.0);
}

#[test]
fn arcs_ij_and_r_forms() {
    let mut s = ParserState::new();
    run(&mut s, "G0 X10 Y0");
    // Half circle CCW around the origin, I/J relative to the start.
    let blocks = run(&mut s, "G3 X-10 Y0 I-10 J0 F600");
    let Block::Arc {
        arc, feed_mm_min, ..
    } = blocks[0]
    else {
        panic!("{blocks:?}")
    };
    assert!(near(arc.centre, PointMm::ZERO));
    assert!((arc.sweep_rad - PI).abs() < 1e-12);
    assert_eq!(feed_mm_min, 600.0);
    // Full circle CW: end = start.
    let blocks = run(&mut s, "G2 X-10 Y0 I10 J0");
    let Block::Arc { arc, .. } = blocks[0] else {
        panic!("{blocks:?}")
    };
    assert!((arc.sweep_rad + 2.0 * PI).abs() < 1e-12);
    // R form: quarter circle from (-10,0) to (0,10), CW, centre origin.
    let blocks = run(&mut s, "G2 X0 Y10 R10");
    let Block::Arc { arc, .. } = blocks[0] else {
        panic!("{blocks:?}")
    };
    assert!(near(arc.centre, PointMm::ZERO), "{arc:?}");
    assert!((arc.sweep_rad + PI / 2.0).abs() < 1e-9);
    // Negative R: the long way (centre on the other side).
    let blocks = run(&mut s, "G2 X10 Y0 R-10");
    let Block::Arc { arc, .. } = blocks[0] else {
        panic!("{blocks:?}")
    };
    assert!(near(arc.centre, p(10.0, 10.0)), "{arc:?}");
    assert!((arc.sweep_rad + 1.5 * PI).abs() < 1e-9);
}

#[test]
fn arc_errors_follow_grbl() {
    let mut s = ParserState::new();
    run(&mut s, "G0 X10 F100");
    assert_eq!(error(&s, "G2 I-10"), 32, "no in-plane end word");
    assert_eq!(error(&s, "G2 X-10"), 35, "no offsets");
    assert_eq!(error(&s, "G2 X-10 I-5"), 33, "end far off the circle");
    assert_eq!(error(&s, "G2 X10 R5"), 33, "R arc ending at its start");
    assert_eq!(error(&s, "G2 X-10 R5"), 34, "radius too small");
    assert_eq!(error(&s, "G2 X-10 I-10 R10"), 36, "R and I: I unused");
    // Within grbl's tolerance: 0.004 mm off is accepted.
    assert!(s.clone().execute("G2 X-10.004 I-10").is_ok());
}

#[test]
fn word_and_modal_errors_follow_grbl() {
    let mut s = ParserState::new();
    for (line, code) in [
        ("10", 1),
        ("G1 X", 2),
        ("X", 2),
        ("S nan", 2),
        ("S NaN", 2),
        ("F inf", 2),
        ("X1.2.3", 2),
        ("F-1", 4),
        ("S-1", 4),
        ("G4 P-1", 4),
        ("G1 X1", 22),
        ("G5", 20),
        ("G28", 20),
        ("G18", 20),
        ("M6", 20),
        ("A1", 20),
        ("G0 G1 X1", 21),
        ("M3 M5", 21),
        ("G1.5", 23),
        ("M3.1", 23),
        ("G0 G92 X0", 24),
        ("X1e3", 20),
        ("X1 X2", 25),
        ("G92", 26),
        ("G10 L20 P1", 26),
        ("N10000000", 27),
        ("G4", 28),
        ("G10 L2 X1", 28),
        ("G55", 29),
        ("G10 L2 P2 X1", 29),
        ("G2 G53 X1", 30),
        ("G0 X1 P2", 36),
        ("G0 X1 I2", 36),
        ("L2", 36),
        ("T256", 38),
        ("G0 X1234567890123456", 2),
        ("G0 X1000000001", 33),
    ] {
        assert_eq!(error(&s, line), code, "{line}");
    }
    run(&mut s, "G80");
    assert_eq!(error(&s, "X1"), 31);
}

#[test]
fn accepted_words_of_laser_cam_output() {
    let mut s = ParserState::new();
    // LaserGRBL / Lightburn style preambles and bodies.
    for line in [
        "%",
        "(Generated by LaserGRBL)",
        "G90 G21 G17 G94 G54 G40 G49 G61 G91.1",
        "M4 S0",
        "N1 G0 X1 Y1 T0 ; comment",
        "G1 F1000 S200",
        "M8",
        "M9",
        "M5",
        "G4 P0.5",
        "N2 G1 X2 Y2*71",
        "M1",
    ] {
        s.execute(line)
            .unwrap_or_else(|e| panic!("{line}: error:{}", e.code()));
    }
    assert_eq!(s.line_number, 0, "grbl: a line without N reports 0");
    s.execute("N7 G0 X0").unwrap();
    assert_eq!(s.line_number, 7);
    assert_eq!(s.units, Units::Millimetres);
}

#[test]
fn dwell_pause_and_program_end() {
    let mut s = ParserState::new();
    run(&mut s, "G91 M4 S100 G1 F100");
    let laser = Laser {
        mode: SpindleMode::Dynamic,
        power: 100.0,
    };
    assert_eq!(
        run(&mut s, "G4 P1.5"),
        [Block::Dwell {
            seconds: 1.5,
            laser
        }]
    );
    let dark = Laser {
        mode: SpindleMode::Off,
        power: 100.0,
    };
    let dwell = Block::Dwell {
        seconds: 1.0,
        laser: dark,
    };
    assert_eq!(run(&mut s, "G0 G4 P1"), [dwell], "G0 state: dark");
    assert_eq!(run(&mut s, "M0"), [Block::Pause]);
    assert_eq!(run(&mut s, "M30"), [Block::End]);
    assert_eq!(s.distance, Distance::Absolute);
    assert_eq!(s.spindle, SpindleMode::Off);
    assert_eq!(s.motion, MotionMode::Linear);
    assert_eq!(s.feed_mm_min, 100.0, "F survives M30 as in grbl 1.1");
}

#[test]
fn jogs_move_the_position_but_change_no_mode() {
    let mut s = ParserState::new();
    run(&mut s, "G0 X5 Y5");
    let jog = |from, to, feed_mm_min| {
        Ok(Some(Block::Jog {
            from,
            to,
            feed_mm_min,
        }))
    };
    assert_eq!(s.jog("G91 X1 F100"), jog(p(5.0, 5.0), p(6.0, 5.0), 100.0));
    assert_eq!(
        s.jog("G53 G20 X1 Y0 F10"),
        jog(p(6.0, 5.0), p(25.4, 0.0), 254.0)
    );
    assert_eq!(s.jog("X25.4 Y0 F100"), Ok(None));
    let moved = ParserState {
        position: p(25.4, 0.0),
        ..ParserState::new()
    };
    assert_eq!(s, moved, "modes unchanged");
    assert_eq!(s.jog("G91 X1"), Err(GrblError::UndefinedFeedRate));
    assert_eq!(s.jog("G1 X1 F100"), Err(GrblError::InvalidJogCommand));
    assert_eq!(s.jog("X1 F100 S5"), Err(GrblError::InvalidJogCommand));
    assert_eq!(s.jog("M3 X1 F100"), Err(GrblError::InvalidJogCommand));
    assert_eq!(s.jog("G17 X1 F100"), Err(GrblError::InvalidJogCommand));
    assert_eq!(s.jog("F100"), Err(GrblError::InvalidJogCommand));
    assert_eq!(s, moved, "refused jogs change nothing");
}

#[test]
fn soft_reset_keeps_position_and_offsets() {
    let mut s = ParserState::new();
    run(&mut s, "G92 X1 Y1");
    run(&mut s, "G20 G91 M3 S9 G1 X1 F5");
    let (position, g92) = (s.position, s.g92);
    s.soft_reset();
    assert_eq!((s.position, s.g92), (position, g92));
    assert_eq!(s.units, Units::Millimetres);
    assert_eq!(s.spindle, SpindleMode::Off);
    assert_eq!(s.feed_mm_min, 0.0);
}

fn finite(b: &Block) -> bool {
    let pt = |p: PointMm| p.x_mm.is_finite() && p.y_mm.is_finite();
    match *b {
        Block::Rapid { from, to } => pt(from) && pt(to),
        Block::Line {
            from,
            to,
            feed_mm_min,
            laser,
        } => {
            pt(from)
                && pt(to)
                && feed_mm_min.is_finite()
                && feed_mm_min > 0.0
                && laser.power.is_finite()
        }
        Block::Arc {
            arc, feed_mm_min, ..
        } => {
            pt(arc.from)
                && pt(arc.to)
                && pt(arc.centre)
                && arc.radius_mm.is_finite()
                && arc.sweep_rad.is_finite()
                && feed_mm_min.is_finite()
                && feed_mm_min > 0.0
        }
        Block::Dwell { seconds, .. } => seconds.is_finite(),
        Block::Jog {
            from,
            to,
            feed_mm_min,
        } => pt(from) && pt(to) && feed_mm_min.is_finite(),
        Block::Pause | Block::End => true,
    }
}

proptest::proptest! {
    #[test]
    fn random_lines_never_panic_and_stay_finite(lines in proptest::collection::vec(
        proptest::prop_oneof![
            proptest::string::string_regex("[GMXYZIJKRFSPLNT0-9. +-]{0,40}").unwrap(),
            proptest::string::string_regex("(G[0-9]{1,2}(\\.[0-9])? ?|[XYIJRF]-?[0-9]{1,16}(\\.[0-9]{0,12})? ?){1,8}").unwrap(),
            ".{0,60}",
        ],
        1..20,
    )) {
        let mut s = ParserState::new();
        for line in &lines {
            let before = s;
            match s.execute(line) {
                Ok(blocks) => proptest::prop_assert!(blocks.iter().all(finite), "{line:?}: {blocks:?}"),
                Err(_) => proptest::prop_assert_eq!(s, before),
            }
            let _ = s.jog(line);
        }
    }

    #[test]
    fn arcs_end_where_programmed(
        x in -100.0f64..100.0, y in -100.0f64..100.0, i in -50.0f64..50.0, j in -50.0f64..50.0,
        clockwise in proptest::bool::ANY,
    ) {
        // End on the start circle: always accepted; point_at(1) is the end.
        let r = libm::hypot(i, j);
        proptest::prop_assume!(r > 0.01);
        let (cx, cy) = (x + i, y + j);
        let angle = libm::atan2(y - cy, x - cx) + 1.0;
        let (ex, ey) = (cx + r * libm::cos(angle), cy + r * libm::sin(angle));
        let mut s = ParserState::new();
        s.execute(&std::format!("G0 X{x:.6} Y{y:.6}")).unwrap();
        let line = std::format!("G{} X{ex:.6} Y{ey:.6} I{i:.6} J{j:.6} F100", if clockwise { 2 } else { 3 });
        let blocks = s.execute(&line).unwrap();
        let Block::Arc { arc, .. } = blocks[0] else { panic!() };
        proptest::prop_assert!(arc.point_at(0.0).distance_to(arc.from) < 1e-9);
        proptest::prop_assert!(arc.point_at(0.5).distance_to(arc.centre) - arc.radius_mm < 1e-9);
        proptest::prop_assert!(arc.sweep_rad.abs() <= 2.0 * PI + 1e-12);
        proptest::prop_assert_eq!(arc.sweep_rad < 0.0, clockwise);
    }
}

/// Issue 25 defect 2: a feed below grbl's 1 mm/min (`MINIMUM_FEED_RATE`)
/// runs at 1 mm/min — G94, G93 inverse time, arcs and jogs alike; the
/// modal F keeps what was programmed.
#[test]
fn feeds_below_the_minimum_run_at_the_minimum() {
    use crate::grbl::block::MIN_FEED_MM_MIN;
    let feed = |b: &[Block]| match b {
        [Block::Line { feed_mm_min, .. } | Block::Arc { feed_mm_min, .. }] => *feed_mm_min,
        other => panic!("{other:?}"),
    };
    let mut s = ParserState::new();
    assert_eq!(MIN_FEED_MM_MIN, 1.0);
    assert_eq!(feed(&run(&mut s, "M3 S1000 G1 X1 F0.0000001")), 1.0);
    assert_eq!(s.feed_mm_min, 0.0000001);
    assert_eq!(feed(&run(&mut s, "G2 X0 Y-1 I-1 J0")), 1.0);
    assert_eq!(feed(&run(&mut s, "G1 X0 Y0 F0.5")), 1.0);
    assert_eq!(feed(&run(&mut s, "G1 X2 F1.5")), 1.5, "above: unchanged");
    // G93: once per 10⁶ minutes over 2 mm is far below the minimum.
    assert_eq!(feed(&run(&mut s, "G93 G1 X4 F0.000001")), 1.0);
    run(&mut s, "G94");
    match s.jog("G91 X1 F0.001") {
        Ok(Some(Block::Jog { feed_mm_min, .. })) => assert_eq!(feed_mm_min, 1.0),
        other => panic!("{other:?}"),
    }
}
