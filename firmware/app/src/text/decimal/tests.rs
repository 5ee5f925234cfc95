extern crate std;

use std::format;
use std::string::String;

use proptest::prelude::*;

use super::*;

fn core_parse(text: &str) -> Option<f64> {
    text.parse::<f64>().ok()
}

fn same(ours: Option<f64>, expected: Option<f64>) -> bool {
    ours.map(f64::to_bits) == expected.map(f64::to_bits)
}

#[test]
fn usual_spellings_match_core() {
    for text in [
        "0",
        "-0",
        "+5",
        ".5",
        "5.",
        "1e-3",
        "2E1",
        "1.e5",
        "-.5e+2",
        "007",
        "0.1",
        "0.3",
        "25.4",
        "1e22",
        "1e23",
        "9007199254740993",
        "1.7976931348623157e308",
        "1.7976931348623159e308",
        "1e309",
        "2.2250738585072011e-308",
        "4.9e-324",
        "2.4703282292062327e-324",
        "2.4703282292062328e-324",
        "1e-400",
        "0e999999999999",
        "123456789012345678901234567890",
        "0.000000000000000000000000000001",
    ] {
        assert!(same(parse_f64(text.as_bytes()), core_parse(text)), "{text}");
    }
}

#[test]
fn malformed_text_is_refused() {
    for bad in [
        "",
        "-",
        "+",
        ".",
        "-.",
        "e3",
        ".e3",
        "1e",
        "1e+",
        "1e-",
        "0x10",
        "1..2",
        "1.2.3",
        "5 ",
        " 5",
        "1e5.5",
        "１",
        "inf",
        "-infinity",
        "nan",
        "1_000",
        "1,5",
        "--1",
    ] {
        assert_eq!(parse_f64(bad.as_bytes()), None, "{bad:?}");
    }
}

#[test]
fn more_significant_digits_than_a_line_holds_are_refused() {
    let digits: String = "1".repeat(MAX_SIGNIFICANT_DIGITS);
    assert!(same(parse_f64(digits.as_bytes()), core_parse(&digits)));
    let longer = format!("{digits}1");
    assert_eq!(parse_f64(longer.as_bytes()), None);
    // Zeros around the significant digits do not count.
    let padded = format!("000{digits}.000e-5");
    assert!(same(parse_f64(padded.as_bytes()), core_parse(&padded)));
}

proptest! {
    /// decode∘encode: every finite f64's text (Display, LowerExp, 17
    /// significant digits) reads back to the same bits.
    #[test]
    fn every_finite_value_round_trips(bits in any::<u64>()) {
        let value = f64::from_bits(bits);
        prop_assume!(value.is_finite());
        for text in [format!("{value}"), format!("{value:e}"), format!("{value:.16e}")] {
            prop_assert!(same(parse_f64(text.as_bytes()), Some(value)), "{}", text);
        }
    }

    /// Random decimal text, from a few digits to many, over the whole
    /// exponent range (overflow to ∞, underflow to 0, subnormals): the
    /// same bits as core's correctly rounded parser.
    #[test]
    fn random_decimals_match_core(
        digits in "[0-9]{1,60}",
        point in 0usize..61,
        exponent in -420i32..420,
        negative in any::<bool>(),
    ) {
        let point = point.min(digits.len());
        let text = format!(
            "{}{}.{}e{exponent}",
            if negative { "-" } else { "" },
            &digits[..point],
            &digits[point..],
        );
        prop_assert!(same(parse_f64(text.as_bytes()), core_parse(&text)), "{}", text);
    }

    /// Exact midpoints between neighbouring doubles (and one unit of the
    /// last digit either side): ties go to the even neighbour.
    #[test]
    fn halfway_cases_round_to_even(mantissa in (1u64 << 52)..(1u64 << 53), k in -22i32..=0) {
        // (2m + 1) · 2^(k-1) = (2m + 1) · 5^(1-k) · 10^(k-1)
        let odd = u128::from(2 * mantissa + 1);
        let scaled = odd * 5u128.pow((1 - k) as u32);
        for digits in [scaled - 1, scaled, scaled + 1] {
            let text = format!("{digits}e{}", k - 1);
            prop_assert!(same(parse_f64(text.as_bytes()), core_parse(&text)), "{}", text);
        }
    }

    /// A G-code word's digits and decimal places: the same bits as the
    /// text `{mantissa}e{exp10}` through core's parser.
    #[test]
    fn scaled_integers_match_core(mantissa in 0u64..1_000_000_000_000_000, exp10 in -40i32..40) {
        let text = format!("{mantissa}e{exp10}");
        prop_assert!(same(Some(scaled_to_f64(mantissa, exp10)), core_parse(&text)), "{}", text);
    }
}
