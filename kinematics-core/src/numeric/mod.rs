//! Numeric helpers shared by the math crates (this one and `galvo-planner`):
//! the finiteness check, a panic-free clamp, the upper-triangular
//! (back-substitution) solve and the `f64` sine and cosine ([`trig`],
//! used by laser-app too). Each crate maps [`NonFinite`] into its own
//! error type (`From`), so `finite(v, "x_cm")?` reads the same in both.
//!
//! `README.md` in this folder lists every own numeric routine of the
//! workspace (here and elsewhere), the measured reason it is not libm's,
//! and its accuracy test.

pub mod trig;

/// A value that must be finite is NaN or infinite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NonFinite {
    /// Which value, with its unit in the name, e.g. `"x_cm"`.
    pub name: &'static str,
}

/// Returns `value` if it is finite, else [`NonFinite`] naming it.
#[inline]
pub fn finite(value: f64, name: &'static str) -> Result<f64, NonFinite> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(NonFinite { name })
    }
}

/// `v` limited to `[lo, hi]`; NaN stays NaN (so solvers still see a
/// diverged iterate), and misordered bounds give `lo` or `hi`, never a
/// panic. Unlike `f64::clamp` it links no float formatting into the
/// firmware (`f64::clamp`'s panic message formats its bounds).
#[inline]
pub fn clamp<F: PartialOrd>(v: F, lo: F, hi: F) -> F {
    if v < lo {
        lo
    } else if v > hi {
        hi
    } else {
        v
    }
}

/// Solves `r · x = b` for upper-triangular `r` by back-substitution (the
/// entries below the diagonal are not read). A zero diagonal gives a
/// non-finite `x`; callers that can meet one check the result.
#[inline]
pub fn back_substitute<const N: usize>(r: &[[f64; N]; N], b: &[f64; N]) -> [f64; N] {
    let mut x = [0.0; N];
    for (k, (row, bk)) in r.iter().zip(b.iter()).enumerate().rev() {
        let tail: f64 = row
            .iter()
            .zip(x.iter())
            .skip(k + 1)
            .map(|(r, xv)| r * xv)
            .sum();
        let diag = row.get(k).copied().unwrap_or(1.0);
        if let Some(xk) = x.get_mut(k) {
            *xk = (bk - tail) / diag;
        }
    }
    x
}

/// `√(x² + y²)` without overflow or underflow in between, within 1 ulp
/// of `libm::hypot` (tested). Infinite if either is infinite (even with a
/// NaN), else NaN if either is NaN. Out of line and unscaled unless a
/// square could leave the `f64` range: 0.5 KB less flash than libm's
/// (whose extra care buys less than an ulp), and faster.
#[inline(never)]
pub fn hypot(x: f64, y: f64) -> f64 {
    // Compared as bits: |v| orders like its bits without the sign, NaN
    // above infinity (soft-float comparisons cost flash).
    const INFINITY: u64 = 0x7ff0_0000_0000_0000;
    let (xb, yb) = (x.to_bits() << 1 >> 1, y.to_bits() << 1 >> 1);
    if xb == INFINITY || yb == INFINITY {
        return f64::INFINITY;
    }
    let exponent = xb.max(yb) >> 52;
    // Powers of two (exact) keep both squares inside the range, subnormal
    // inputs included; NaN passes through.
    let (scale, unscale) = if exponent > 1023 + 500 {
        (
            f64::from_bits(0x1a70_0000_0000_0000),
            f64::from_bits(0x6570_0000_0000_0000),
        ) // 2^∓600
    } else if exponent < 1023 - 500 {
        (
            f64::from_bits(0x6570_0000_0000_0000),
            f64::from_bits(0x1a70_0000_0000_0000),
        ) // 2^±600
    } else {
        return libm::sqrt(x * x + y * y);
    };
    let (x, y) = (x * scale, y * scale);
    libm::sqrt(x * x + y * y) * unscale
}

#[cfg(test)]
mod tests;
