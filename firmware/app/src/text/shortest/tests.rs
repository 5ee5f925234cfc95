extern crate std;

use std::format;
use std::string::String;

use proptest::prelude::*;

use super::*;

struct Ours(f64);

impl fmt::Display for Ours {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_finite(self.0, f)
    }
}

fn ryu_text(v: f64) -> String {
    String::from(ryu::Buffer::new().format_finite(v))
}

/// `p` and the values one bit either side of it.
fn neighbours(p: f64) -> [f64; 3] {
    let bits = p.to_bits();
    [
        p,
        f64::from_bits(bits + 1),
        f64::from_bits(bits.saturating_sub(1)),
    ]
}

#[test]
fn edge_values_read_as_ryu_writes_them() {
    let mut values = std::vec![
        0.0,
        -0.0,
        1.0,
        0.1,
        0.3,
        2.5e-7,
        1e-5,
        1e-4,
        123.456,
        1e15,
        1e16,
        1e17,
        1e22,
        1e23,
        9007199254740993.0,
        5e-324,
        1e-323,
        2.2250738585072014e-308,
        2.225073858507201e-308,
        f64::MAX,
        f64::MIN_POSITIVE,
        f64::EPSILON,
        1.0 / 3.0,
        2.0f64.powi(-1074),
        2.0f64.powi(1023),
        2.0f64.powi(-1022),
        2.0f64.powi(-1000),
        2.0f64.powi(60),
    ];
    // Powers of two and ten, and their neighbours: the interval is lopsided
    // at a power of two; a power of ten tests the exponent estimate.
    for i in -1074..1024 {
        let p = 2.0f64.powi(i);
        values.extend(neighbours(p));
    }
    for i in -323..309 {
        let p: f64 = format!("1e{i}").parse().unwrap_or(1.0);
        values.extend(neighbours(p));
    }
    for v in values {
        for v in [v, -v] {
            assert_eq!(format!("{}", Ours(v)), ryu_text(v), "{v:e}");
        }
    }
}

proptest! {
    /// Any finite value: the same text as Ryū's.
    #[test]
    fn any_value_reads_as_ryu_writes_it(bits in any::<u64>()) {
        let v = f64::from_bits(bits);
        prop_assume!(v.is_finite());
        prop_assert_eq!(format!("{}", Ours(v)), ryu_text(v));
    }

    /// Values with few significant digits (where ties and trailing zeros
    /// live): the same text as Ryū's.
    #[test]
    fn short_decimals_read_as_ryu_writes_them(mantissa in 1u64..100_000, exp10 in -330i32..310) {
        let v: f64 = format!("{mantissa}e{exp10}").parse().unwrap_or(0.0);
        prop_assume!(v.is_finite());
        prop_assert_eq!(format!("{}", Ours(v)), ryu_text(v));
    }
}
