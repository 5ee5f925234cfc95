//! G-code words of one line: `letter number` pairs, as grbl reads them.
//!
//! Like grbl, spaces and tabs are ignored everywhere (`G 1 X 1 0` is
//! `G1 X10`), letters are case-insensitive, `( … )` comments are skipped
//! and `;` ends the line. Beyond grbl: `%` ends the line too (program
//! delimiters of G-code files) and a trailing `*NN` checksum is accepted
//! and ignored. Numbers are `[+|-]digits[.digits]`, no exponent, read by
//! integer arithmetic (no `core` float parsing is linked into the firmware).

use super::error::GrblError;

/// Largest number of integer digits a value may have; more is
/// [`GrblError::BadNumberFormat`]. It bounds every value below 1e15, so no
/// later arithmetic can overflow to infinity or NaN.
const MAX_INTEGER_DIGITS: u32 = 15;
/// Significant digits accumulated exactly (below 2^53); later fraction
/// digits are dropped.
const MAX_SIGNIFICANT_DIGITS: u32 = 15;

/// One word: an upper-case letter and its value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Word {
    /// `b'A'..=b'Z'`.
    pub letter: u8,
    /// The value, finite, |value| < 1e15.
    pub value: f64,
}

/// Iterator over the words of one line.
#[derive(Debug, Clone)]
pub struct Words<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Words<'a> {
    /// The words of `line` (without its terminator).
    pub fn new(line: &'a str) -> Self {
        Self {
            bytes: line.as_bytes(),
            at: 0,
        }
    }

    /// Skips spaces, tabs and comments; returns the next meaningful byte.
    fn peek(&mut self) -> Option<u8> {
        while let Some(&byte) = self.bytes.get(self.at) {
            match byte {
                b' ' | b'\t' => self.at += 1,
                b'(' => {
                    self.at = match self.bytes[self.at..].iter().position(|&b| b == b')') {
                        Some(close) => self.at + close + 1,
                        None => self.bytes.len(),
                    }
                }
                b';' | b'%' | b'*' => self.at = self.bytes.len(),
                _ => return Some(byte),
            }
        }
        None
    }

    fn next_byte_if(&mut self, wanted: impl Fn(u8) -> bool) -> Option<u8> {
        let byte = self.peek()?;
        if wanted(byte) {
            self.at += 1;
            Some(byte)
        } else {
            None
        }
    }

    /// Reads `[+|-]digits[.digits]`.
    fn number(&mut self) -> Result<f64, GrblError> {
        let negative = self.next_byte_if(|b| b == b'-' || b == b'+') == Some(b'-');
        let (mut mantissa, mut significant, mut fraction_digits) = (0u64, 0u32, 0i32);
        let (mut integer_digits, mut any_digit, mut seen_point) = (0u32, false, false);
        while let Some(byte) = self.next_byte_if(|b| b.is_ascii_digit() || b == b'.') {
            if byte == b'.' {
                if seen_point {
                    return Err(GrblError::BadNumberFormat);
                }
                seen_point = true;
                continue;
            }
            any_digit = true;
            let digit = u64::from(byte - b'0');
            if !seen_point {
                integer_digits += u32::from(mantissa != 0 || digit != 0);
                if integer_digits > MAX_INTEGER_DIGITS {
                    return Err(GrblError::BadNumberFormat);
                }
            }
            if significant < MAX_SIGNIFICANT_DIGITS {
                mantissa = mantissa * 10 + digit;
                significant += u32::from(mantissa != 0);
                fraction_digits += i32::from(seen_point);
            }
        }
        if !any_digit {
            return Err(GrblError::BadNumberFormat);
        }
        // `mantissa`e-`fraction_digits`, correctly rounded by the same
        // decimal conversion the command line uses.
        let value = crate::text::decimal::scaled_to_f64(mantissa, -fraction_digits);
        Ok(if negative { -value } else { value })
    }
}

impl Iterator for Words<'_> {
    type Item = Result<Word, GrblError>;

    fn next(&mut self) -> Option<Self::Item> {
        let byte = self.peek()?;
        self.at += 1;
        if !byte.is_ascii_alphabetic() {
            // Stop after the first error.
            self.at = self.bytes.len();
            return Some(Err(GrblError::ExpectedCommandLetter));
        }
        let letter = byte.to_ascii_uppercase();
        Some(match self.number() {
            Ok(value) => Ok(Word { letter, value }),
            Err(e) => {
                self.at = self.bytes.len();
                Err(e)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn words(line: &str) -> Result<Vec<(char, f64)>, GrblError> {
        Words::new(line)
            .map(|w| w.map(|w| (w.letter as char, w.value)))
            .collect()
    }

    #[test]
    fn reads_words_like_grbl() {
        assert_eq!(
            words("g1x10.5 Y-2 f+300"),
            Ok(std::vec![
                ('G', 1.0),
                ('X', 10.5),
                ('Y', -2.0),
                ('F', 300.0)
            ])
        );
        assert_eq!(words("G 1 X 1 0"), Ok(std::vec![('G', 1.0), ('X', 10.0)]));
        assert_eq!(words("X.5 Y5."), Ok(std::vec![('X', 0.5), ('Y', 5.0)]));
        assert_eq!(words("G91.1"), Ok(std::vec![('G', 91.1)]));
    }

    #[test]
    fn comments_and_checksums_are_skipped() {
        assert_eq!(
            words("G0 (move to X5) X1 ; rest X9"),
            Ok(std::vec![('G', 0.0), ('X', 1.0)])
        );
        assert_eq!(words("(unclosed X5"), Ok(std::vec![]));
        assert_eq!(words("%"), Ok(std::vec![]));
        assert_eq!(
            words("N3 G1 X1*57"),
            Ok(std::vec![('N', 3.0), ('G', 1.0), ('X', 1.0)])
        );
    }

    #[test]
    fn bad_words_name_grbl_errors() {
        assert_eq!(words("10"), Err(GrblError::ExpectedCommandLetter));
        assert_eq!(words("G1 #1"), Err(GrblError::ExpectedCommandLetter));
        assert_eq!(words("X"), Err(GrblError::BadNumberFormat));
        assert_eq!(words("X-"), Err(GrblError::BadNumberFormat));
        assert_eq!(words("X."), Err(GrblError::BadNumberFormat));
        assert_eq!(words("X1.2.3"), Err(GrblError::BadNumberFormat));
        // An exponent reads as another word (E), which the parser refuses.
        assert_eq!(words("X1e3"), Ok(std::vec![('X', 1.0), ('E', 3.0)]));
        assert_eq!(words("X1234567890123456"), Err(GrblError::BadNumberFormat));
        assert_eq!(
            words("X123456789012345"),
            Ok(std::vec![('X', 123456789012345.0)])
        );
        assert_eq!(words("X0000000000000000001"), Ok(std::vec![('X', 1.0)]));
    }

    #[test]
    fn decimals_read_exactly() {
        for (text, value) in [("0.1", 0.1), ("-12.345", -12.345), ("0.000001", 1e-6)] {
            let line = std::format!("X{text}");
            assert_eq!(words(&line), Ok(std::vec![('X', value)]));
        }
    }

    proptest::proptest! {
        #[test]
        fn any_text_gives_finite_words_or_an_error(line in ".{0,200}") {
            for word in Words::new(&line).flatten() {
                proptest::prop_assert!(word.value.is_finite() && word.value.abs() < 1e15);
            }
        }

        #[test]
        fn formatted_decimals_read_back(thousandths in -1_000_000_000i64..1_000_000_000) {
            let value = thousandths as f64 / 1000.0;
            let line = std::format!("X{}", crate::text::Fixed::<3>(value));
            proptest::prop_assert_eq!(words(&line), Ok(std::vec![('X', value)]));
        }
    }
}
