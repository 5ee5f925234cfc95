//! The G-code model's interpreter and geometry.

use super::*;
use crate::safety::gcode_piece::arc;

#[test]
fn arcs_follow_grbl_and_distances_measure_the_programmed_part() {
    // G2 X0 Y-10 I-10 J0 from (10, 0): a quarter, clockwise.
    let q = arc(
        [10.0, 0.0],
        [0.0, -10.0],
        Some(-10.0),
        Some(0.0),
        None,
        true,
    )
    .unwrap();
    assert!((q.length_mm() - 5.0 * std::f64::consts::PI).abs() < 1e-9);
    assert!(q.distance_mm([10.0f64.sqrt() * 5.0f64.sqrt(), -50f64.sqrt()]) < 1e-9);
    // The rest of the circle is off it: (-10, 0) is 14.1 mm from both ends.
    assert!((q.distance_mm([-10.0, 0.0]) - 200f64.sqrt()).abs() < 1e-9);
    // A full circle by I/J only; R < 0 takes the long way.
    let full = arc([5.0, 5.0], [5.0, 5.0], Some(5.0), Some(-5.0), None, true).unwrap();
    assert!((full.length_mm() - 2.0 * std::f64::consts::PI * 50f64.sqrt()).abs() < 1e-6);
    let long = arc([0.0, 0.0], [30.0, 30.0], None, None, Some(-30.0), false).unwrap();
    let Piece::Arc { centre, .. } = long else {
        panic!()
    };
    assert!(dist(centre, [30.0, 0.0]) < 1e-9, "{centre:?}");
    assert!((long.length_mm() - 45.0 * std::f64::consts::PI).abs() < 1e-6);
    assert!(dist(long.end(), [30.0, 30.0]) < 1e-9);
}

#[test]
fn sessions_follow_replies_holds_and_resets() {
    let lines = [
        (0, "> target galvo"),
        (1, "ok"),
        (2, "> G0 X1 Y2"),
        (3, "> G1 X3 F60"),
        (4, "ok"),
        (5, "error:33"),
        (6, "> M3 S10"),
        (7, "ok"),
        (8, "> G20 G91 G1 X1 F6"),
        (9, "ok"),
        (10, ">> 0x21"),
        (20, ">> 0x7e"),
        (30, ">> 0x18"),
        (40, "> G2 X7 Y5 I1 J0"),
        (41, "ok"),
    ];
    let transcript = Transcript {
        lines: lines.iter().map(|(t, l)| (*t, (*l).to_owned())).collect(),
        ..Transcript::default()
    };
    let here = |_: Spot, _: u64| Some([5.0, 5.0]);
    let s = sessions(&transcript, &[], &here);
    assert_eq!(s.len(), 2, "{s:?}");
    // The refused G1 is not there; G20 G91 moves by 1 inch from (1, 2).
    let first = &s[0];
    assert_eq!(
        (first.spot, first.start_us, first.end_us),
        (Spot::Galvo, 2, 30)
    );
    assert_eq!(first.holds, [(10, 20)]);
    assert_eq!(first.motions.len(), 2);
    assert_eq!(
        first.motions[0].piece,
        Piece::Line {
            a: [5.0, 5.0],
            b: [1.0, 2.0]
        }
    );
    assert!(!first.motions[0].lit && first.motions[0].planned_s.is_none());
    let inch = first.motions[1];
    assert_eq!(
        inch.piece,
        Piece::Line {
            a: [1.0, 2.0],
            b: [26.4, 2.0]
        }
    );
    assert!(inch.lit);
    assert!(
        (inch.planned_s.unwrap() - 10.0).abs() < 1e-9,
        "25.4 mm at 152.4 mm/min"
    );
    // After the reset: modes reset (dark, F0 → 1 mm/min), the start
    // from the spot; the arc is not lit.
    let arc = s[1].motions[0];
    assert!(!arc.lit);
    assert!((arc.piece.length_mm() - std::f64::consts::PI).abs() < 1e-9);
    assert_eq!(s[1].end_us, u64::MAX);
}

#[test]
fn only_g_code_lines_have_words() {
    assert_eq!(
        words("G1 X1.5 y-2 (c) ; x"),
        Some(vec![('G', 1.0), ('X', 1.5), ('Y', -2.0)])
    );
    for line in [
        "status",
        "stop",
        "goto 1 2",
        "set dwell_ms 3",
        "$X",
        "target galvo",
    ] {
        assert_eq!(words(line), None, "{line}");
    }
}
