//! The shortest decimal that reads back as the same `f64`, in Ryū's
//! layout (`ryu::Buffer::format_finite`: `0.25`, `1e-7`, `1.5e300`,
//! `1000000000000000.0`), by exact big-integer arithmetic (Steele & White's
//! free-format digits) instead of Ryū's tables: [`super::Shortest`]'s text.

use core::cmp::Ordering;
use core::fmt;

use super::big::Big;

/// Most digits the shortest form of an `f64` has.
const MAX_DIGITS: usize = 17;

/// Shortest digits of a finite, non-zero, positive `v`, closest to `v`
/// among those (ties to even): `v ≈ 0.d₁d₂…dₙ × 10^point`.
struct Digits {
    digits: [u8; MAX_DIGITS],
    len: usize,
    point: i32,
}

impl Digits {
    fn of(v: f64) -> Self {
        let bits = v.to_bits();
        let biased = ((bits >> 52) & 0x7ff) as i32;
        let fraction = bits & ((1 << 52) - 1);
        let (f, e) = if biased == 0 {
            (fraction, -1074)
        } else {
            (fraction | (1 << 52), biased - 1075)
        };
        // The gap below is half the gap above at a power of two.
        let lower_closer = fraction == 0 && biased > 1;
        let even = f & 1 == 0;
        // v = r/s; the round-trip interval is [r - minus, r + plus] / s,
        // its ends included when f is even.
        let shift = 1 + u32::from(lower_closer);
        let mut r = Big::from_u64(f);
        r.shl(shift);
        let mut s = Big::from_u64(1 << shift);
        let mut plus = Big::from_u64(1 << (shift - 1));
        let mut minus = Big::from_u64(1);
        if e >= 0 {
            for big in [&mut r, &mut plus, &mut minus] {
                big.shl(e as u32);
            }
        } else {
            s.shl(e.unsigned_abs());
        }
        // 10^point bounds the interval: an estimate from below (the bit
        // length times a little less than log10 2), then up to the first
        // power of ten above the interval's top.
        let log2 = e + 63 - f.leading_zeros() as i32;
        let mut point = (log2 * 78_913) >> 18;
        for _ in 0..point.unsigned_abs() {
            if point >= 0 {
                s.mul_add(10, 0);
            } else {
                for big in [&mut r, &mut plus, &mut minus] {
                    big.mul_add(10, 0);
                }
            }
        }
        let above = |r: &Big, plus: &Big, s: &Big| {
            let top = r.plus(plus).compare(s);
            top == Ordering::Greater || (even && top == Ordering::Equal)
        };
        while above(&r, &plus, &s) {
            s.mul_add(10, 0);
            point += 1;
        }
        let mut out = Self {
            digits: [0; MAX_DIGITS],
            len: 0,
            point,
        };
        loop {
            for big in [&mut r, &mut plus, &mut minus] {
                big.mul_add(10, 0);
            }
            let mut digit = 0u8;
            while r.sub_if_ge(&s) {
                digit += 1;
            }
            let low = match r.compare(&minus) {
                Ordering::Less => true,
                Ordering::Equal => even,
                Ordering::Greater => false,
            };
            let high = above(&r, &plus, &s);
            if !(low || high) && out.len + 1 < MAX_DIGITS {
                out.push(digit);
                continue;
            }
            let up = match (low, high) {
                (true, false) => false,
                (false, true) => true,
                _ => match r.plus(&r).compare(&s) {
                    Ordering::Less => false,
                    Ordering::Greater => true,
                    Ordering::Equal => digit & 1 == 1,
                },
            };
            out.push(digit);
            if up {
                out.round_up();
            }
            return out;
        }
    }

    fn push(&mut self, digit: u8) {
        self.digits[self.len] = digit;
        self.len += 1;
    }

    /// Adds one unit of the last digit, carrying (`0.999` → `1`).
    fn round_up(&mut self) {
        while self.len > 0 {
            self.digits[self.len - 1] += 1;
            if self.digits[self.len - 1] < 10 {
                return;
            }
            self.len -= 1;
        }
        self.digits[0] = 1;
        self.len = 1;
        self.point += 1;
    }

    fn write(&self, f: &mut fmt::Formatter<'_>, from: usize, to: usize) -> fmt::Result {
        for d in &self.digits[from.min(self.len)..to.min(self.len)] {
            fmt::Write::write_char(f, char::from(b'0' + d))?;
        }
        Ok(())
    }
}

fn zeros(f: &mut fmt::Formatter<'_>, count: i32) -> fmt::Result {
    for _ in 0..count {
        f.write_str("0")?;
    }
    Ok(())
}

/// Writes finite `v` as `ryu::Buffer::format_finite` does.
pub(super) fn write_finite(v: f64, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    if v.is_sign_negative() {
        f.write_str("-")?;
    }
    if v == 0.0 {
        return f.write_str("0.0");
    }
    let d = Digits::of(v.abs());
    let (len, point) = (d.len as i32, d.point);
    if (len..=16).contains(&point) {
        // 1234e7 → 12340000000.0
        d.write(f, 0, d.len)?;
        zeros(f, point - len)?;
        f.write_str(".0")
    } else if (1..=16).contains(&point) {
        // 1234e-2 → 12.34
        d.write(f, 0, point as usize)?;
        f.write_str(".")?;
        d.write(f, point as usize, d.len)
    } else if (-4..=0).contains(&point) {
        // 1234e-6 → 0.001234
        f.write_str("0.")?;
        zeros(f, -point)?;
        d.write(f, 0, d.len)
    } else {
        // 1234e30 → 1.234e33, 1e30
        d.write(f, 0, 1)?;
        if len > 1 {
            f.write_str(".")?;
            d.write(f, 1, d.len)?;
        }
        // Through u64 formatting: the one integer writer linked anyway.
        let exp = point - 1;
        f.write_str(if exp < 0 { "e-" } else { "e" })?;
        write!(f, "{}", u64::from(exp.unsigned_abs()))
    }
}

#[cfg(test)]
mod tests;
