//! Errors the command line reports back as `error: <reason>`.

use core::fmt;

use crate::text::Interval;

/// A word quoted in an error message, truncated to fit.
pub type Word = heapless::String<24>;

/// Copies `text` into a [`Word`], cutting it at 21 bytes and adding `...`
/// when longer (always at a character boundary: lines are ASCII).
pub fn word(text: &str) -> Word {
    let mut out = Word::new();
    if text.len() <= 24 {
        let _ = out.push_str(text);
    } else {
        let cut = (0..=21)
            .rev()
            .find(|&i| text.is_char_boundary(i))
            .unwrap_or(0);
        let _ = out.push_str(text.get(..cut).unwrap_or(""));
        let _ = out.push_str("...");
    }
    out
}

/// Why a command line was refused. Nothing changes when a line is refused.
#[derive(Debug, Clone, PartialEq)]
pub enum CommandError {
    /// The first word is not a command.
    UnknownCommand(Word),
    /// A required argument is missing; names what was expected.
    MissingArgument(&'static str),
    /// An argument is present but not valid; names what was expected.
    InvalidArgument {
        /// What the argument should have been.
        expected: &'static str,
        /// What was given.
        got: Word,
    },
    /// More arguments than the command takes.
    UnexpectedArgument(Word),
    /// A numeric value outside its allowed range.
    OutOfRange {
        /// What the value is.
        what: &'static str,
        /// Lowest accepted value.
        min: f64,
        /// Highest accepted value.
        max: f64,
    },
    /// The command is valid but cannot run now (e.g. unreachable target);
    /// the message says why.
    Rejected(&'static str),
}

impl fmt::Display for CommandError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CommandError::UnknownCommand(w) => {
                write!(f, "unknown command '{w}'")
            }
            CommandError::MissingArgument(what) => write!(f, "missing argument: {what}"),
            CommandError::InvalidArgument { expected, got } => {
                write!(f, "expected {expected}, got '{got}'")
            }
            CommandError::UnexpectedArgument(w) => write!(f, "unexpected argument '{w}'"),
            CommandError::OutOfRange { what, min, max } => {
                write!(f, "{what} out of range {}", Interval(*min, *max))
            }
            CommandError::Rejected(why) => f.write_str(why),
        }
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for CommandError {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "{}", defmt::Display2Format(self))
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::string::ToString;

    #[test]
    fn long_words_are_truncated_with_ellipsis() {
        assert_eq!(word("short").as_str(), "short");
        let long = "abcdefghijklmnopqrstuvwxyz0123456789";
        assert_eq!(word(long).as_str(), "abcdefghijklmnopqrstu...");
        assert_eq!(word(&long[..24]).as_str(), &long[..24]);
    }

    #[test]
    fn messages_name_the_problem() {
        assert_eq!(
            CommandError::UnknownCommand(word("frob")).to_string(),
            "unknown command 'frob'"
        );
        assert_eq!(
            CommandError::OutOfRange {
                what: "dwell_ms",
                min: 0.0,
                max: 60000.0
            }
            .to_string(),
            "dwell_ms out of range [0, 60000]"
        );
    }
}
