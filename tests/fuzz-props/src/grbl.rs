//! Console bytes → grbl realtime filter → line assembly → classification →
//! G-code parser / `$` commands, as the console and the sequencer's grbl
//! session handle them.
//!
//! Properties:
//! * nothing panics;
//! * realtime bytes never reach a line, and every other byte does (the
//!   filter splits, never drops);
//! * a refused line (`error:N`, grbl's number) changes nothing in the
//!   parser state;
//! * an accepted line's blocks are finite, within the coordinate limit,
//!   chained (each starts where the previous one ended, the first where
//!   the state was) and end where the state now is; feeds are positive,
//!   arcs sweep at most one turn and end on their circle;
//! * `$G` and `$#` of any reachable state format without error.

use std::collections::BTreeSet;

use laser_app::cli::line::LineAssembler;
use laser_app::grbl::classify::{LineKind, classify};
use laser_app::grbl::parser::COORDINATE_LIMIT_MM;
use laser_app::grbl::realtime::{Filtered, Realtime, split};
use laser_app::grbl::report::{PARAMETER_LINES, write_parameter_line, write_parser_state};
use laser_app::grbl::system::{SystemCommand, parse_system};
use laser_app::grbl::{Block, ParserState, PointMm};

/// What one input exercised.
#[derive(Debug, Default)]
pub struct Summary {
    /// G-code and `$` lines.
    pub lines: usize,
    /// Accepted G-code lines and jogs.
    pub accepted: usize,
    /// grbl error numbers of refused lines.
    pub errors: BTreeSet<u8>,
    /// Kinds of blocks produced.
    pub blocks: BTreeSet<&'static str>,
    /// Realtime commands taken out.
    pub realtime: usize,
}

fn kind(block: &Block) -> &'static str {
    match block {
        Block::Rapid { .. } => "rapid",
        Block::Line { .. } => "line",
        Block::Arc { .. } => "arc",
        Block::Dwell { .. } => "dwell",
        Block::Pause => "pause",
        Block::End => "end",
        Block::Jog { .. } => "jog",
    }
}

fn finite(p: PointMm) -> bool {
    let ok = |v: f64| v.is_finite() && v.abs() <= COORDINATE_LIMIT_MM;
    ok(p.x_mm) && ok(p.y_mm)
}

/// Checks the blocks of one accepted line against the state before and
/// after it.
fn check_blocks(line: &str, blocks: &[Block], before: &ParserState, after: &ParserState) {
    let mut at = before.position;
    for block in blocks {
        let (from, to) = match *block {
            Block::Rapid { from, to } => (from, to),
            Block::Line {
                from,
                to,
                feed_mm_min,
                ..
            }
            | Block::Jog {
                from,
                to,
                feed_mm_min,
            } => {
                assert!(
                    feed_mm_min.is_finite() && feed_mm_min > 0.0,
                    "{line:?}: feed {feed_mm_min}"
                );
                (from, to)
            }
            Block::Arc {
                arc, feed_mm_min, ..
            } => {
                assert!(feed_mm_min.is_finite() && feed_mm_min > 0.0, "{line:?}");
                assert!(
                    arc.radius_mm.is_finite()
                        && arc.sweep_rad.abs() <= std::f64::consts::TAU + 1e-9,
                    "{line:?}: {arc:?}"
                );
                assert!(finite(arc.centre), "{line:?}: centre {arc:?}");
                // grbl's end check: within 0.5 mm or 0.1 % of the radius.
                let end_radius = arc.centre.distance_to(arc.to);
                let slack = (0.005f64).max((0.5f64).min(0.001 * arc.radius_mm));
                assert!(
                    (end_radius - arc.radius_mm).abs() <= slack + 1e-9 || !end_radius.is_finite(),
                    "{line:?}: arc ends off its circle {arc:?}"
                );
                (arc.from, arc.to)
            }
            Block::Dwell { seconds, .. } => {
                assert!(seconds.is_finite() && seconds >= 0.0, "{line:?}");
                continue;
            }
            Block::Pause | Block::End => continue,
        };
        assert!(finite(from) && finite(to), "{line:?}: {block:?}");
        assert_eq!(from, at, "{line:?}: blocks not chained");
        at = to;
    }
    assert_eq!(at, after.position, "{line:?}: state not at the last end");
}

fn report_formats(state: &ParserState) {
    let mut text = String::new();
    write_parser_state(&mut text, state).expect("$G formats");
    assert!(text.starts_with("[GC:") && text.ends_with(']'), "{text}");
    for index in 0..PARAMETER_LINES {
        text.clear();
        write_parameter_line(&mut text, index, state).expect("$# formats");
        assert!(text.starts_with('[') && text.ends_with(']'), "{text}");
    }
}

/// One complete line through the grbl layer.
fn handle_line(line: &str, state: &mut ParserState, summary: &mut Summary) {
    let before = *state;
    let result = match classify(line) {
        LineKind::Product => return,
        LineKind::Gcode => state.execute(line).map(|b| b.to_vec()),
        LineKind::System => match parse_system(line) {
            Ok(SystemCommand::Jog(text)) => state.jog(text).map(|b| b.into_iter().collect()),
            Ok(_) => Ok(Vec::new()),
            Err(e) => Err(e),
        },
    };
    summary.lines += 1;
    match result {
        Ok(blocks) => {
            summary.accepted += 1;
            check_blocks(line, &blocks, &before, state);
            summary.blocks.extend(blocks.iter().map(kind));
            report_formats(state);
        }
        Err(error) => {
            summary.errors.insert(error.code());
            assert_eq!(
                *state,
                before,
                "{line:?}: refused (error:{}) but changed the state",
                error.code()
            );
        }
    }
}

/// Runs the grbl properties on `data`; panics when one fails.
pub fn check(data: &[u8]) -> Summary {
    let mut assembler = LineAssembler::new();
    let mut state = ParserState::new();
    let mut summary = Summary::default();
    let mut line_bytes = 0usize;
    for item in split(data) {
        match item {
            Filtered::Realtime(command) => {
                summary.realtime += 1;
                assert!(
                    !matches!(command, Realtime::Ignored(b) if b < 0x80),
                    "{command:?}"
                );
            }
            Filtered::Line(byte) => {
                assert!(
                    Realtime::from_byte(byte).is_none(),
                    "0x{byte:02x} reached a line"
                );
                line_bytes += 1;
                if let Some(Ok(line)) = assembler.push(byte) {
                    handle_line(line.as_str(), &mut state, &mut summary);
                }
            }
        }
    }
    let taken = data
        .iter()
        .filter(|&&b| Realtime::from_byte(b).is_some())
        .count();
    assert_eq!(
        taken + line_bytes,
        data.len(),
        "bytes dropped by the filter"
    );
    assert_eq!(taken, summary.realtime);
    summary
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_gcode_like_bytes_keep_every_property() {
        const ALPHABET: &[u8] = b"GMXYZFIJKRSPLNT0123456789.-+ $=#()\r\n?!~\x18\x85\x91";
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut accepted = 0;
        for _ in 0..300 {
            let data: Vec<u8> = (0..400)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    ALPHABET[(x % ALPHABET.len() as u64) as usize]
                })
                .collect();
            accepted += check(&data).accepted;
        }
        assert!(
            accepted > 0,
            "random lines never parse: the check proves little"
        );
    }
}
