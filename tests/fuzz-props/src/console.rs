//! Console bytes → line assembler → command parser → settings, as the USB
//! console task and the sequencer handle them.
//!
//! Properties:
//! * nothing panics;
//! * every line terminator (CR, LF, or CRLF counted once) yields exactly
//!   one outcome, and no other byte does;
//! * each outcome is what the assembler's rules give for the bytes of its
//!   line (an independent model: backspace/DEL edit, longer than
//!   [`MAX_LINE_LEN`] → too long, any other non-printable byte → invalid);
//! * every accepted command prints (`{:?}`, command-line syntax) as text
//!   that parses back to the same command;
//! * a refused `set` changes nothing in the settings;
//! * an accepted `set` stores the value, keeps the settings valid and
//!   savable, and `get` then prints a value that, sent back with `set`,
//!   is the same value and changes nothing.

use std::collections::BTreeSet;

use laser_app::cli::line::{Line, LineAssembler, LineError, MAX_LINE_LEN};
use laser_app::cli::parse::parse_line;
use laser_app::command::Command;
use laser_app::settings::{ParamLine, ParamSpec, Settings};

/// What one input exercised.
#[derive(Debug, Default)]
pub struct Summary {
    /// Complete lines (outcomes).
    pub lines: usize,
    /// Lines refused by the assembler (too long, invalid byte).
    pub line_errors: usize,
    /// Lines refused by the parser.
    pub parse_errors: usize,
    /// Blank and comment lines.
    pub blank: usize,
    /// Names of the commands that parsed.
    pub commands: BTreeSet<&'static str>,
    /// `set`s the settings accepted.
    pub sets_accepted: usize,
    /// `set`s that parsed but the settings refused (cross-parameter rules).
    pub sets_refused: usize,
}

/// Runs the console properties on `data`; panics when one fails.
pub fn check(data: &[u8]) -> Summary {
    let mut assembler = LineAssembler::new();
    let mut settings = Settings::default();
    let mut summary = Summary::default();
    // Raw bytes of the current line (terminators left out).
    let mut raw = Vec::new();
    let mut previous_was_cr = false;
    for &byte in data {
        let lf_after_cr = byte == b'\n' && previous_was_cr;
        let terminates = (byte == b'\r' || byte == b'\n') && !lf_after_cr;
        previous_was_cr = byte == b'\r';
        let outcome = assembler.push(byte);
        assert_eq!(
            outcome.is_some(),
            terminates,
            "byte 0x{byte:02x} after {raw:?}: an outcome exactly at each line end"
        );
        match outcome {
            Some(result) => {
                assert_eq!(result, expected_line(&raw), "line bytes {raw:?}");
                summary.lines += 1;
                match result {
                    Ok(line) => handle_line(line.as_str(), &mut settings, &mut summary),
                    Err(_) => summary.line_errors += 1,
                }
                raw.clear();
            }
            None if lf_after_cr => {}
            None => raw.push(byte),
        }
    }
    let pending = expected_line(&raw).map_or(true, |line| !line.is_empty());
    assert_eq!(assembler.is_mid_line(), pending, "unfinished line {raw:?}");
    summary
}

const BACKSPACE: u8 = 0x08;
const DELETE: u8 = 0x7f;

fn printable(byte: u8) -> bool {
    byte == b'\t' || (0x20..0x7f).contains(&byte)
}

/// The line the bytes spell after backspace/DEL editing, or `None` when it
/// grew past [`MAX_LINE_LEN`] on the way.
fn expected_text(raw: &[u8]) -> Option<Vec<u8>> {
    let mut text = Vec::new();
    for &b in raw {
        if b == BACKSPACE || b == DELETE {
            text.pop();
        } else {
            text.push(b);
            if text.len() > MAX_LINE_LEN {
                return None;
            }
        }
    }
    Some(text)
}

/// What the assembler must report for a line of `raw` bytes (the module
/// rules of `cli/line.rs`, written independently of its code).
fn expected_line(raw: &[u8]) -> Result<Line, LineError> {
    let text = expected_text(raw).ok_or(LineError::TooLong)?;
    if let Some(&bad) = raw
        .iter()
        .find(|&&b| b != BACKSPACE && b != DELETE && !printable(b))
    {
        return Err(LineError::InvalidByte(bad));
    }
    let text = String::from_utf8(text).expect("printable ASCII is UTF-8");
    let mut line = Line::new();
    line.push_str(&text).expect("at most MAX_LINE_LEN bytes");
    Ok(line)
}

/// One complete line through the parser and, for commands that change
/// settings, into `settings` as the sequencer applies them.
fn handle_line(line: &str, settings: &mut Settings, summary: &mut Summary) {
    let command = match parse_line(line) {
        Ok(Some(command)) => command,
        Ok(None) => {
            summary.blank += 1;
            return;
        }
        Err(error) => {
            assert!(!error.to_string().is_empty(), "{line:?}: empty error");
            summary.parse_errors += 1;
            return;
        }
    };
    summary.commands.insert(command.name());
    let printed = format!("{command:?}");
    assert_eq!(
        parse_line(&printed),
        Ok(Some(command)),
        "{line:?} printed as {printed:?}"
    );
    match command {
        Command::Set { param, value } => set(settings, param, value, summary),
        Command::Get(param) => {
            let shown = get(settings, param);
            assert!(
                shown == settings.get(param),
                "get {} printed {shown}, holds {}",
                param.name,
                settings.get(param)
            );
        }
        // The sequencer stores these two directly in its settings.
        Command::Laser(mode) => settings.laser_mode = mode,
        Command::Planner(planner) => settings.galvo.planner = planner,
        _ => {}
    }
}

/// `set param value` as the sequencer does it (no run active, so no run
/// re-check), with the properties of accepted and refused values.
fn set(settings: &mut Settings, param: &'static ParamSpec, value: f64, summary: &mut Summary) {
    let before = *settings;
    let before_record = settings.to_record();
    if settings.set(param, value).is_err() {
        summary.sets_refused += 1;
        assert!(
            *settings == before,
            "refused set {} {value} changed settings",
            param.name
        );
        assert!(
            settings.to_record() == before_record,
            "refused set {} {value} changed the saved form",
            param.name
        );
        return;
    }
    summary.sets_accepted += 1;
    assert!(
        settings.get(param) == value,
        "set {} {value} stored {}",
        param.name,
        settings.get(param)
    );
    assert!(
        settings.validate().is_ok(),
        "accepted set left invalid settings"
    );
    assert_eq!(
        Settings::from_record(&settings.to_record()),
        Ok(*settings),
        "settings after set {} {value} do not survive save/load",
        param.name
    );
    // `get` prints the value; sending it back is the same value and a
    // no-op.
    let shown = get(settings, param);
    assert!(
        shown == value,
        "set {} {value}: get shows {shown}",
        param.name
    );
    let again = format!("set {} {}", param.name, shown_text(settings, param));
    match parse_line(&again) {
        Ok(Some(Command::Set { param: p, value: v })) if p.name == param.name && v == value => {}
        other => panic!("{again:?} parsed as {other:?}"),
    }
    let after = *settings;
    assert!(settings.set(param, shown).is_ok(), "{again:?} refused");
    assert!(*settings == after, "{again:?} changed settings");
}

/// The value text of `get param` (`name = value  # help …`).
fn shown_text(settings: &Settings, param: &ParamSpec) -> String {
    let line = ParamLine(param, settings.get(param)).to_string();
    let rest = line
        .strip_prefix(param.name)
        .and_then(|r| r.strip_prefix(" = "))
        .unwrap_or_else(|| panic!("get line {line:?}"));
    let (value, help) = rest
        .split_once("  # ")
        .unwrap_or_else(|| panic!("get line {line:?}"));
    assert!(help.starts_with(param.help), "get line {line:?}");
    value.to_owned()
}

/// The value `get param` shows, read back with the command line's parser.
fn get(settings: &Settings, param: &'static ParamSpec) -> f64 {
    let text = shown_text(settings, param);
    laser_app::cli::args::parse_number(&text, param.name, f64::MIN, f64::MAX)
        .unwrap_or_else(|e| panic!("get {} shows {text:?}: {e}", param.name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_model_agrees_with_the_documented_rules() {
        assert_eq!(expected_line(b"help").as_deref(), Ok("help"));
        assert_eq!(expected_line(b"helx\x08p").as_deref(), Ok("help"));
        assert_eq!(expected_line(b"he\x00lp"), Err(LineError::InvalidByte(0)));
        assert_eq!(
            expected_line(&[b'a'; MAX_LINE_LEN + 1]),
            Err(LineError::TooLong)
        );
        assert_eq!(
            expected_line(&[b'a'; MAX_LINE_LEN]).map(|l| l.len()),
            Ok(MAX_LINE_LEN)
        );
    }

    #[test]
    fn a_session_of_lines_is_checked_line_by_line() {
        let s = check(
            b"help\r\nset dwell_ms 250\nset grid.cols 13\nset pitch.id 0\nget dwell_ms\r\
              laser dwell\nbogus\n\xff\n# note\n\nstatus",
        );
        assert_eq!(s.lines, 10, "the unterminated `status` is no line yet");
        assert_eq!((s.sets_accepted, s.sets_refused), (1, 2));
        assert_eq!((s.line_errors, s.parse_errors, s.blank), (1, 1, 2));
        assert_eq!(
            s.commands.iter().copied().collect::<Vec<_>>(),
            ["get", "help", "laser", "set"]
        );
    }
}
