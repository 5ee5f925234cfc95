//! Argument cursor over a command line's words, with typed, range-checked
//! accessors that produce [`CommandError`]s naming what was expected.

use super::error::{CommandError, word};

/// The remaining words of a command line.
#[derive(Debug, Clone)]
pub struct Args<'a> {
    words: core::str::SplitAsciiWhitespace<'a>,
}

impl<'a> Args<'a> {
    /// Words of `text`, split on ASCII whitespace.
    pub fn new(text: &'a str) -> Self {
        Self {
            words: text.split_ascii_whitespace(),
        }
    }

    /// The next word, if any.
    pub fn next_word(&mut self) -> Option<&'a str> {
        self.words.next()
    }

    /// The next word; `what` names it in the error when missing.
    pub fn word(&mut self, what: &'static str) -> Result<&'a str, CommandError> {
        self.words.next().ok_or(CommandError::MissingArgument(what))
    }

    /// The next word parsed as a finite number within `[min, max]`.
    pub fn number(&mut self, what: &'static str, min: f64, max: f64) -> Result<f64, CommandError> {
        let text = self.word(what)?;
        parse_number(text, what, min, max)
    }

    /// The next word parsed as an integer within `[min, max]`.
    pub fn integer(&mut self, what: &'static str, min: i32, max: i32) -> Result<i32, CommandError> {
        let text = self.word(what)?;
        parse_integer(text, what, min, max)
    }

    /// Fails if words remain.
    pub fn finish(mut self) -> Result<(), CommandError> {
        match self.words.next() {
            None => Ok(()),
            Some(extra) => Err(CommandError::UnexpectedArgument(word(extra))),
        }
    }
}

/// Parses a finite decimal number within `[min, max]`.
pub fn parse_number(
    text: &str,
    what: &'static str,
    min: f64,
    max: f64,
) -> Result<f64, CommandError> {
    let value = crate::text::decimal::parse_f64(text.as_bytes())
        .filter(|v| v.is_finite())
        .ok_or_else(|| CommandError::InvalidArgument {
            expected: what,
            got: word(text),
        })?;
    if !(min..=max).contains(&value) {
        return Err(CommandError::OutOfRange { what, min, max });
    }
    Ok(value)
}

/// Parses a decimal integer within `[min, max]`.
pub fn parse_integer(
    text: &str,
    what: &'static str,
    min: i32,
    max: i32,
) -> Result<i32, CommandError> {
    let value: i32 = text.parse().map_err(|_| CommandError::InvalidArgument {
        expected: what,
        got: word(text),
    })?;
    if !(min..=max).contains(&value) {
        return Err(CommandError::OutOfRange {
            what,
            min: f64::from(min),
            max: f64::from(max),
        });
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_checked_for_finiteness_and_range() {
        assert_eq!(parse_number("2.5", "x_cm", -20.0, 20.0), Ok(2.5));
        assert_eq!(parse_number("-20", "x_cm", -20.0, 20.0), Ok(-20.0));
        assert!(matches!(
            parse_number("nan", "x_cm", -20.0, 20.0),
            Err(CommandError::InvalidArgument { .. })
        ));
        assert!(matches!(
            parse_number("inf", "x_cm", -20.0, 20.0),
            Err(CommandError::InvalidArgument { .. })
        ));
        assert!(matches!(
            parse_number("1e9", "x_cm", -20.0, 20.0),
            Err(CommandError::OutOfRange { .. })
        ));
        assert!(matches!(
            parse_number("2,5", "x_cm", -20.0, 20.0),
            Err(CommandError::InvalidArgument { .. })
        ));
    }

    #[test]
    fn integers_reject_fractions_and_overflow() {
        assert_eq!(parse_integer("-6", "xi", -6, 6), Ok(-6));
        assert!(parse_integer("1.5", "xi", -6, 6).is_err());
        assert!(parse_integer("99999999999", "xi", -6, 6).is_err());
        assert!(matches!(
            parse_integer("7", "xi", -6, 6),
            Err(CommandError::OutOfRange { .. })
        ));
    }

    #[test]
    fn finish_rejects_extra_words() {
        let mut args = Args::new("goto 1 2 3");
        assert_eq!(args.word("command"), Ok("goto"));
        assert_eq!(args.number("x", -9.0, 9.0), Ok(1.0));
        assert_eq!(args.number("y", -9.0, 9.0), Ok(2.0));
        assert_eq!(
            args.finish(),
            Err(CommandError::UnexpectedArgument(word("3")))
        );
        assert_eq!(
            Args::new("goto").skip_command().number("x_cm", -1.0, 1.0),
            Err(CommandError::MissingArgument("x_cm"))
        );
    }

    #[test]
    fn usual_number_spellings_are_accepted() {
        for (text, value) in [
            ("+5", 5.0),
            (".5", 0.5),
            ("5.", 5.0),
            ("-0", 0.0),
            ("1e-3", 1e-3),
            ("2E1", 20.0),
        ] {
            assert_eq!(parse_number(text, "v", -100.0, 100.0), Ok(value), "{text}");
        }
        for bad in ["", "-", "e3", "1e", "0x10", "1..2", "5 ", "１"] {
            assert!(parse_number(bad, "v", -100.0, 100.0).is_err(), "{bad:?}");
        }
    }

    proptest::proptest! {
        /// Decimal text of any finite f64 (shortest round-trip form, as
        /// `cargo xtask calib fit --output` prints coefficients, and the
        /// exponent form) parses back to exactly the same value.
        #[test]
        fn decimal_text_round_trips_exactly(bits in proptest::prelude::any::<u64>()) {
            extern crate std;
            let value = f64::from_bits(bits);
            proptest::prop_assume!(value.is_finite());
            for text in [std::format!("{value}"), std::format!("{value:e}")] {
                proptest::prop_assert_eq!(
                    parse_number(&text, "v", f64::MIN, f64::MAX).map(f64::to_bits),
                    Ok(value.to_bits()),
                    "{}", text
                );
            }
        }

        /// encode∘decode: every finite value's text parses back exactly
        /// with the command line's own number parser.
        #[test]
        fn shortest_round_trips_through_the_parser(bits in proptest::prelude::any::<u64>()) {
            extern crate std;
            let v = f64::from_bits(bits);
            proptest::prop_assume!(v.is_finite());
            let text = std::format!("{}", crate::text::Shortest(v));
            let back = parse_number(&text, "v", f64::MIN, f64::MAX);
            proptest::prop_assert_eq!(back.map(|b| b == v), Ok(true), "{}", text);
        }
    }

    impl<'a> Args<'a> {
        fn skip_command(mut self) -> Self {
            self.next_word();
            self
        }
    }
}
