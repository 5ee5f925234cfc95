//! Command-line text → [`Command`].

use super::args::Args;
use super::error::{CommandError, word};
use crate::command::Command;

/// Parses one command line. Blank lines and `#` comments parse to `None`
/// (they are acknowledged with `ok` and do nothing, so a file of commands
/// with comments can be pasted into the terminal).
pub fn parse_line(line: &str) -> Result<Option<Command>, CommandError> {
    let text = line.trim();
    if text.is_empty() || text.starts_with('#') {
        return Ok(None);
    }
    let mut args = Args::new(text);
    let name = args.word("command")?;
    let command = if name.eq_ignore_ascii_case("help") {
        Command::Help
    } else if name.eq_ignore_ascii_case("version") {
        Command::Version
    } else if name.eq_ignore_ascii_case("status") {
        Command::Status
    } else {
        return Err(CommandError::UnknownCommand(word(name)));
    };
    args.finish()?;
    Ok(Some(command))
}

/// One line per command for `help`.
pub const HELP_LINES: &[&str] = &[
    "help                 this list",
    "version              firmware version and build",
    "status               uptime, build, state",
];

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::string::ToString;

    #[test]
    fn parses_the_basic_commands_case_insensitively() {
        assert_eq!(parse_line("help"), Ok(Some(Command::Help)));
        assert_eq!(parse_line("  VERSION \t"), Ok(Some(Command::Version)));
        assert_eq!(parse_line("Status"), Ok(Some(Command::Status)));
    }

    #[test]
    fn blank_lines_and_comments_do_nothing() {
        assert_eq!(parse_line(""), Ok(None));
        assert_eq!(parse_line("   \t "), Ok(None));
        assert_eq!(parse_line("# set err.dx.c0 1.0"), Ok(None));
    }

    #[test]
    fn unknown_words_are_named() {
        assert_eq!(
            parse_line("frobnicate now"),
            Err(CommandError::UnknownCommand(word("frobnicate")))
        );
        assert_eq!(
            parse_line("~~~").map_err(|e| e.to_string()),
            Err("unknown command '~~~'".to_string())
        );
    }

    #[test]
    fn extra_arguments_are_refused() {
        assert_eq!(
            parse_line("version 2"),
            Err(CommandError::UnexpectedArgument(word("2")))
        );
    }

    #[test]
    fn every_command_in_help_parses() {
        for line in HELP_LINES {
            let name = line.split_ascii_whitespace().next().unwrap_or("");
            // Commands whose help shows arguments are checked in their own tests.
            if line.contains('<') {
                continue;
            }
            assert!(
                parse_line(name).is_ok(),
                "help lists '{name}' but it does not parse"
            );
        }
    }
}
