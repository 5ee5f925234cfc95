//! Decimal text → `f64`, correctly rounded (round half to even), in about
//! 1.5 KB of code and no tables: the firmware's number parser (command line
//! and G-code words). `core`'s parser carries a 10 KB table of powers of
//! five; this one takes Clinger's fast path (an exact integer times or over
//! an exact power of ten: one rounding) for the usual short numbers and
//! otherwise divides exact big integers.
//!
//! Accepted text is `core`'s finite syntax: `[+|-]` digits with an
//! optional `.` (digits on at least one side), then an optional
//! `e`/`E` `[+|-]` digits. `inf` and `nan` are not numbers here.

use super::big::Big;

/// Most significant digits (leading and trailing zeros not counted) read:
/// more than any command line holds ([`crate::command::MAX_LINE_LEN`]).
pub const MAX_SIGNIFICANT_DIGITS: usize = 128;

/// The value of `text` (the whole of it), or `None` if it is not a finite
/// decimal in the syntax above or has more than
/// [`MAX_SIGNIFICANT_DIGITS`]. Magnitudes beyond `f64::MAX` give ±∞.
pub fn parse_f64(text: &[u8]) -> Option<f64> {
    let (negative, rest) = match text.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, text),
    };
    let mantissa_len = rest
        .iter()
        .position(|b| !(b.is_ascii_digit() || *b == b'.'))
        .unwrap_or(rest.len());
    let (mantissa, exponent_text) = rest.split_at(mantissa_len);
    let points = mantissa.iter().filter(|b| **b == b'.').count();
    if points > 1 || mantissa.len() == points {
        return None;
    }
    let exponent = match exponent_text.split_first() {
        None => 0,
        Some((b'e' | b'E', digits)) => parse_exponent(digits)?,
        Some(_) => return None,
    };
    // Decimal exponent of the mantissa's last digit.
    let fraction_digits = mantissa
        .iter()
        .position(|b| *b == b'.')
        .map_or(0, |point| mantissa.len() - point - 1);
    let exp10 = exponent.saturating_sub(fraction_digits as i32);
    let value = digits_to_f64(mantissa, exp10)?;
    Some(if negative { -value } else { value })
}

/// `[+|-]digits`, saturated far beyond any finite `f64` exponent.
fn parse_exponent(text: &[u8]) -> Option<i32> {
    let (negative, digits) = match text.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, text),
    };
    if digits.is_empty() || !digits.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let magnitude = digits.iter().fold(0i32, |acc, d| {
        (acc * 10 + i32::from(d - b'0')).min(1_000_000)
    });
    Some(if negative { -magnitude } else { magnitude })
}

/// `mantissa × 10^exp10`, correctly rounded: `mantissa` is a whole number
/// below 10^15 (a G-code word's digits).
pub fn scaled_to_f64(mantissa: u64, exp10: i32) -> f64 {
    let mut digits = [b'0'; 20];
    let mut at = digits.len();
    let mut rest = mantissa;
    loop {
        at -= 1;
        digits[at] = b'0' + (rest % 10) as u8;
        rest /= 10;
        if rest == 0 {
            break;
        }
    }
    // 20 digits hold any u64, far below MAX_SIGNIFICANT_DIGITS.
    digits_to_f64(&digits[at..], exp10).unwrap_or(f64::INFINITY)
}

/// `digits × 10^exp10` where `digits` are ASCII digits with at most one
/// `.` to skip (the decimal point, already counted in `exp10`).
fn digits_to_f64(digits: &[u8], exp10: i32) -> Option<f64> {
    let digit_values = || digits.iter().filter(|b| **b != b'.').map(|b| b - b'0');
    // Significant digits: without leading zeros, trailing zeros moved into
    // the exponent.
    let leading = digit_values().take_while(|d| *d == 0).count();
    let trailing = digit_values().rev().take_while(|d| *d == 0).count();
    let total = digit_values().count();
    if leading == total {
        return Some(0.0);
    }
    let significant = total - leading - trailing;
    if significant > MAX_SIGNIFICANT_DIGITS {
        return None;
    }
    let exp10 = exp10.saturating_add(trailing as i32);
    let significant_digits = || digit_values().skip(leading).take(significant);
    // Clinger's fast path: both factors exact, one rounding.
    if significant <= 15 && exp10.unsigned_abs() <= 22 {
        let whole = significant_digits().fold(0u64, |acc, d| acc * 10 + u64::from(d));
        let power = (0..exp10.unsigned_abs()).fold(1.0f64, |p, _| p * 10.0);
        return Some(if exp10 < 0 {
            whole as f64 / power
        } else {
            whole as f64 * power
        });
    }
    // value ∈ [10^(magnitude - 1), 10^magnitude)
    let magnitude = significant as i32 + exp10;
    if magnitude > 310 {
        return Some(f64::INFINITY);
    }
    if magnitude < -324 {
        return Some(0.0);
    }
    let mut whole = Big::ZERO;
    for d in significant_digits() {
        whole.mul_add(10, u32::from(d));
    }
    Some(exact_quotient_to_f64(whole, exp10))
}

/// `whole × 10^exp10` rounded to the nearest `f64` (ties to even) by exact
/// division: a 64- to 66-bit quotient and whether a remainder is left.
/// `whole` < 10^128, `exp10` within the bounds `digits_to_f64` checked.
#[inline(never)]
fn exact_quotient_to_f64(whole: Big, exp10: i32) -> f64 {
    let (mut num, mut den) = (whole, Big::ZERO);
    den.0[0] = 1;
    let power = if exp10 >= 0 { &mut num } else { &mut den };
    for _ in 0..exp10.unsigned_abs() {
        power.mul_add(10, 0);
    }
    // num · 2^s / den ∈ [2^63, 2^65]
    let s = 64 - (num.bits() - den.bits());
    if s >= 0 {
        num.shl(s as u32);
    } else {
        den.shl(s.unsigned_abs());
    }
    den.shl(65);
    let mut quotient = 0u128;
    for _ in 0..66 {
        quotient = (quotient << 1) | u128::from(num.sub_if_ge(&den));
        den.shr1();
    }
    let inexact = num.0.iter().any(|l| *l != 0);
    round_to_f64(quotient, s, inexact)
}

/// `quotient × 2^-s` (plus a little more if `inexact`) rounded to the
/// nearest `f64`, ties to even; subnormal, zero or ∞ where it falls there.
fn round_to_f64(quotient: u128, s: i32, inexact: bool) -> f64 {
    let bits = 128 - quotient.leading_zeros() as i32;
    // Drop bits below a 53-bit mantissa or below 2^-1074.
    let shift = (bits - 53).max(s - 1074);
    if shift > 100 {
        return 0.0;
    }
    let shift = shift as u32;
    let mut mantissa = (quotient >> shift) as u64;
    let dropped = quotient & ((1u128 << shift) - 1);
    let half = 1u128 << (shift - 1);
    if dropped > half || (dropped == half && (inexact || mantissa & 1 == 1)) {
        mantissa += 1;
    }
    let mut exponent = shift as i32 - s + 1074;
    if mantissa == 1 << 53 {
        mantissa >>= 1;
        exponent += 1;
    }
    if exponent > 2045 {
        return f64::INFINITY;
    }
    // Exponent field + 1 where the mantissa has its implicit bit (2^52).
    f64::from_bits(((exponent as u64) << 52) + mantissa)
}

#[cfg(test)]
mod tests;
