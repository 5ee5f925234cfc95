//! The whole input path: bytes → realtime filter → line assembly →
//! classification → G-code parser or `$` commands.

extern crate std;
use super::classify::{LineKind, classify};
use super::realtime::{Filtered, split};
use super::system::{SystemCommand, parse_system};
use super::*;
use crate::cli::line::LineAssembler;
use std::vec::Vec;

/// Feeds `chunks` through the input path; returns the realtime commands
/// and, per line, its kind and whether it was accepted.
fn drive(chunks: &[Vec<u8>], state: &mut ParserState) -> (usize, Vec<(LineKind, bool)>) {
    let (mut assembler, mut realtime, mut lines) = (LineAssembler::new(), 0, Vec::new());
    for chunk in chunks {
        for item in split(chunk) {
            let byte = match item {
                Filtered::Realtime(_) => {
                    realtime += 1;
                    continue;
                }
                Filtered::Line(byte) => byte,
            };
            let Some(Ok(line)) = assembler.push(byte) else {
                continue;
            };
            let kind = classify(&line);
            let accepted = match kind {
                LineKind::Gcode => state.execute(&line).is_ok(),
                LineKind::System => match parse_system(&line) {
                    Ok(SystemCommand::Jog(text)) => state.jog(text).is_ok(),
                    other => other.is_ok(),
                },
                LineKind::Product => true,
            };
            lines.push((kind, accepted));
        }
    }
    (realtime, lines)
}

#[test]
fn a_streamed_job_with_realtime_bytes_mid_line() {
    let job = b"G21 G90\r\nM4 S500\r\nG0 X-10 Y-10\r\nG1 X1?0 F1200\r\nG2 X10 Y10 I0 J10!\r\n~G1 X-10\x91\r\nM5\r\n$G\r\nstatus\r\nG1 X1 X2\r\n";
    let mut state = ParserState::new();
    let chunks: Vec<Vec<u8>> = job.chunks(7).map(<[u8]>::to_vec).collect();
    let (realtime, lines) = drive(&chunks, &mut state);
    assert_eq!(realtime, 4, "? ! ~ 0x91");
    let kinds: Vec<LineKind> = lines.iter().map(|l| l.0).collect();
    assert_eq!(kinds[..7], [LineKind::Gcode; 7]);
    assert_eq!(
        kinds[7..],
        [LineKind::System, LineKind::Product, LineKind::Gcode]
    );
    let accepted: Vec<bool> = lines.iter().map(|l| l.1).collect();
    assert_eq!(
        accepted,
        [true, true, true, true, true, true, true, true, true, false]
    );
    assert_eq!(
        state.position,
        PointMm {
            x_mm: -10.0,
            y_mm: 10.0
        }
    );
}

proptest::proptest! {
    #[test]
    fn random_bytes_never_panic(chunks in proptest::collection::vec(
        proptest::collection::vec(proptest::prop_oneof![
            proptest::num::u8::ANY,
            proptest::sample::select(b"GMXYFIJRSP0123456789.-$=\n ?!~".to_vec()),
        ], 0..64),
        0..16,
    )) {
        let mut state = ParserState::new();
        let _ = drive(&chunks, &mut state);
        proptest::prop_assert!(state.position.x_mm.is_finite() && state.position.y_mm.is_finite());
        proptest::prop_assert!(state.feed_mm_min.is_finite() && state.power.is_finite());
    }
}
