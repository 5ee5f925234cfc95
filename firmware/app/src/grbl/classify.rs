//! One console, two languages: which one a line is in.
//!
//! A line is grbl's when its first meaningful character is `$` (a system
//! command), a G-code comment (`(`, `;`, `%`), or a letter followed by a
//! number (a G-code word such as `G1`, `M3`, `N10`, `X5`; spaces between
//! letter and number allowed, as grbl ignores them), or a letter standing
//! alone (`X`, `S nan`: grbl answers those with `error:2`). The product's
//! command words are two letters or more (`goto`, `pattern`, …) and its
//! comments start with `#`, so they never look like that.

/// The language of a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LineKind {
    /// G-code (words, or only a comment): the G-code parser.
    Gcode,
    /// A `$` system command.
    System,
    /// The product's own command line (also blank lines and `#` comments,
    /// which it answers with `ok` as before).
    Product,
}

/// Classifies one line (terminator removed).
pub fn classify(line: &str) -> LineKind {
    let mut bytes = line
        .bytes()
        .skip_while(|b| *b == b' ' || *b == b'\t')
        .peekable();
    match bytes.next() {
        Some(b'$') => LineKind::System,
        Some(b'(' | b';' | b'%') => LineKind::Gcode,
        Some(letter) if letter.is_ascii_alphabetic() => {
            // A word letter standing alone (`X`, `S nan`, `F=1`): grbl's
            // parser answers it with its error number; no product word
            // has a single letter.
            let alone = bytes.peek().is_none_or(|b| !b.is_ascii_alphanumeric());
            let mut rest = bytes.skip_while(|b| *b == b' ' || *b == b'\t');
            match rest.next() {
                Some(b) if b.is_ascii_digit() || matches!(b, b'-' | b'+' | b'.') => LineKind::Gcode,
                _ if alone => LineKind::Gcode,
                _ => LineKind::Product,
            }
        }
        _ => LineKind::Product,
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::cli::error::CommandError;
    use crate::cli::parse::parse_line;
    use std::string::ToString;
    use std::vec::Vec;

    /// Every command word of the product (cli/parse.rs).
    const PRODUCT_WORDS: &[&str] = &[
        "help", "version", "status", "stop", "params", "target", "planner", "galvo", "save",
        "pattern", "goto", "grid", "laser", "model", "set", "get", "home", "trace", "arm", "servo",
    ];

    #[test]
    fn gcode_lines_are_gcode() {
        for line in [
            "G1 X10 Y5 F300",
            "g0x0",
            "M3 S1000",
            "N10 G1 X1",
            "X5 Y-2",
            "  G 1 X1",
            "T0",
            "F.5",
            "X",
            "S nan",
            " y ",
            "F=1",
            "(comment)",
            "; comment",
            "%",
        ] {
            assert_eq!(classify(line), LineKind::Gcode, "{line:?}");
        }
        for line in ["$", "$$", "$J=G91 X1 F100", " $X", "$RST=*"] {
            assert_eq!(classify(line), LineKind::System, "{line:?}");
        }
    }

    #[test]
    fn every_product_command_classifies_as_product() {
        for word in PRODUCT_WORDS {
            // The list holds real commands: none is unknown to the parser.
            assert!(
                !matches!(parse_line(word), Err(CommandError::UnknownCommand(_))),
                "{word} is not a command"
            );
            for line in [
                word.to_string(),
                std::format!("{word} 1 2"),
                word.to_uppercase(),
            ] {
                assert_eq!(classify(&line), LineKind::Product, "{line:?}");
            }
        }
        for line in ["", "   ", "# note", "#G1 X1", "pattern line 0 0 1 1"] {
            assert_eq!(classify(line), LineKind::Product, "{line:?}");
        }
    }

    #[test]
    fn readme_command_table_words_are_all_known() {
        // First word of every row of the command reference's table.
        let readme = include_str!("../../../../docs/console.md");
        let table: Vec<&str> = readme
            .lines()
            .skip_while(|l| !l.starts_with("| command |"))
            .skip(2)
            .take_while(|l| l.starts_with("| `"))
            .filter_map(|l| l.trim_start_matches("| `").split([' ', '`', '\\']).next())
            .collect();
        assert!(table.len() >= 10, "command table not found: {table:?}");
        for word in table {
            assert!(
                PRODUCT_WORDS.contains(&word),
                "{word} missing from PRODUCT_WORDS"
            );
            assert_eq!(classify(word), LineKind::Product);
        }
    }
}
