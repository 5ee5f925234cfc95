//! Number formatting for replies without `core`'s float formatting, whose
//! Grisu/Dragon code and tables cost ~12 KB of the firmware's flash (budget
//! 384 KiB, SPEC §2). The bottom layer of the application: everything that
//! prints numbers (settings, commands, sequencer, command line) uses it,
//! and it uses nothing of the application.
//!
//! [`Shortest`] prints the shortest text that parses back to the same
//! `f64` (in Ryū's layout, by exact big-integer arithmetic: no tables):
//! for values users read
//! back and may paste again (`get`, `params`, ranges). [`Fixed`] prints a
//! fixed number of decimals by integer arithmetic: for status lines.
//! [`Interval`] prints a closed range `[min, max]` in the shortest form.
//! [`ReplyText`] is one reply line, [`reply_text`] formats into one.
//! [`decimal`] reads numbers back: decimal text to `f64`, correctly rounded.

mod big;
pub mod decimal;
mod shortest;

use core::fmt::{self, Write as _};

/// `f64` in its shortest round-trip form (`1000`, `0.25`, `2.96e-5`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shortest(pub f64);

impl fmt::Display for Shortest {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        if !v.is_finite() {
            return f.write_str(if v.is_nan() {
                "NaN"
            } else if v > 0.0 {
                "inf"
            } else {
                "-inf"
            });
        }
        // Whole numbers (parameter values, limits) print without ".0".
        if v == libm::trunc(v) && v.abs() < 1e15 {
            return fmt::Display::fmt(&Int(v as i64), f);
        }
        shortest::write_finite(v, f)
    }
}

pub use kinematics_core::error::Int;

/// `f64` rounded to `DECIMALS` places (`Fixed::<3>(5.0)` → `5.000`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fixed<const DECIMALS: u32>(pub f64);

impl<const DECIMALS: u32> fmt::Display for Fixed<DECIMALS> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_fixed(self.0, DECIMALS, f)
    }
}

/// [`Fixed`]'s text, one copy for every `DECIMALS`.
fn write_fixed(value: f64, decimals: u32, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    let scale = 10u64.pow(decimals);
    let scaled = libm::round(libm::fabs(value) * scale as f64);
    // Beyond 2^53 the decimals are meaningless: shortest form instead.
    if !scaled.is_finite() || scaled >= 9.0e15 {
        return fmt::Display::fmt(&Shortest(value), f);
    }
    let units = scaled as u64;
    let sign = if value < 0.0 && units != 0 { "-" } else { "" };
    let (whole, fraction) = (units / scale, units % scale);
    if decimals == 0 {
        write!(f, "{sign}{whole}")
    } else {
        write!(
            f,
            "{sign}{whole}.{fraction:0width$}",
            width = decimals as usize
        )
    }
}

/// A closed range `[min, max]` with both ends in their [`Shortest`] form
/// (`[0, 60000]`): how parameter ranges read in `params` lines and errors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval(pub f64, pub f64);

impl fmt::Display for Interval {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}, {}]", Shortest(self.0), Shortest(self.1))
    }
}

/// Longest reply line, bytes (longer lines are cut).
pub const REPLY_LINE_LEN: usize = 120;

/// Text of one reply line.
pub type ReplyText = heapless::String<REPLY_LINE_LEN>;

/// Formats into a reply line, cutting it at [`REPLY_LINE_LEN`] bytes.
pub fn reply_text(args: fmt::Arguments<'_>) -> ReplyText {
    let mut out = Truncating(ReplyText::new());
    let _ = out.write_fmt(args);
    out.0
}

struct Truncating(ReplyText);

impl fmt::Write for Truncating {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for c in s.chars() {
            if self.0.push(c).is_err() {
                break;
            }
        }
        Ok(())
    }
}

/// `text` without leading and trailing whitespace: `str::trim`'s result
/// (the same Unicode `White_Space` set, tested against
/// `char::is_whitespace`) without linking core's 256 B whitespace table.
pub fn trim(text: &str) -> &str {
    text.trim_matches(is_white_space)
}

/// Whether `c` has the Unicode `White_Space` property (as
/// `char::is_whitespace`).
fn is_white_space(c: char) -> bool {
    matches!(
        c,
        '\t'..='\r'
            | ' '
            | '\u{85}'
            | '\u{a0}'
            | '\u{1680}'
            | '\u{2000}'..='\u{200a}'
            | '\u{2028}'
            | '\u{2029}'
            | '\u{202f}'
            | '\u{205f}'
            | '\u{3000}'
    )
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::format;

    #[test]
    fn white_space_is_chars_whitespace() {
        for c in (0..=0x10_ffff).filter_map(char::from_u32) {
            assert_eq!(is_white_space(c), c.is_whitespace(), "{c:?}");
        }
        for text in ["", "  ", " help ", "\u{3000}x\u{a0}\t", "a b\n", "\u{2029}"] {
            assert_eq!(trim(text), text.trim(), "{text:?}");
        }
    }

    #[test]
    fn fixed_rounds_to_its_decimals() {
        assert_eq!(format!("{}", Fixed::<3>(5.0)), "5.000");
        assert_eq!(format!("{}", Fixed::<3>(-3.0)), "-3.000");
        assert_eq!(format!("{}", Fixed::<2>(11.496)), "11.50");
        assert_eq!(format!("{}", Fixed::<1>(-0.04)), "0.0");
        assert_eq!(format!("{}", Fixed::<1>(-11.35)), "-11.4");
        assert_eq!(format!("{}", Fixed::<3>(0.0005)), "0.001");
        assert_eq!(format!("{}", Fixed::<0>(2.5)), "3");
        assert_eq!(format!("{}", Fixed::<2>(f64::NAN)), "NaN");
        assert_eq!(format!("{}", Fixed::<2>(1e300)), "1e300");
    }

    #[test]
    fn shortest_prints_whole_numbers_plainly() {
        assert_eq!(format!("{}", Shortest(1000.0)), "1000");
        assert_eq!(format!("{}", Shortest(-135.0)), "-135");
        assert_eq!(format!("{}", Shortest(0.25)), "0.25");
        assert_eq!(format!("{}", Shortest(-0.0)), "0");
        assert_eq!(
            format!("{}", Shortest(-999_999_999_999_999.0)),
            "-999999999999999"
        );
        assert_eq!(format!("{}", Shortest(-1.5e-7)), "-1.5e-7");
        for v in [0, 7, -7, i64::from(i16::MIN), i64::MAX, i64::MIN] {
            assert_eq!(format!("{}", Int(v)), format!("{v}"));
        }
        assert_eq!(format!("{}", Shortest(f64::NEG_INFINITY)), "-inf");
    }

    #[test]
    fn intervals_print_both_ends_in_the_shortest_form() {
        assert_eq!(format!("{}", Interval(0.0, 60_000.0)), "[0, 60000]");
        assert_eq!(format!("{}", Interval(-0.01, 2.5e-7)), "[-0.01, 2.5e-7]");
    }

    proptest::proptest! {
        /// Fixed agrees with core's formatting away from rounding ties.
        #[test]
        fn fixed_matches_core(v in -1.0e6f64..1.0e6) {
            let scaled = (v * 1000.0).abs();
            proptest::prop_assume!((scaled - scaled.trunc() - 0.5).abs() > 1e-6);
            let ours = format!("{}", Fixed::<3>(v));
            let core = format!("{v:.3}");
            let core = if core == "-0.000" { "0.000".into() } else { core };
            proptest::prop_assert_eq!(ours, core);
        }
    }

    #[test]
    fn reply_text_is_cut_at_the_limit() {
        let long = [b'x'; 300];
        let text = core::str::from_utf8(&long).unwrap_or("");
        let line = reply_text(format_args!("{text}"));
        assert_eq!(line.len(), REPLY_LINE_LEN);
        assert_eq!(
            reply_text(format_args!("a={} b={}", 1, 2.5)).as_str(),
            "a=1 b=2.5"
        );
    }
}
