//! `f64` sine and cosine for the no_std crates (radians).
//!
//! One small implementation instead of libm's `sin`/`cos`/`sincos`, whose
//! argument reduction (`rem_pio2`, exact for any `f64` up to 1e308) made
//! them 5.3 KB of the firmware image; these are 1.4 KB. Our angles are a
//! few radians; here the reduction is exact for |x| ≤
//! [`EXACT_REDUCTION_MAX`] (1.6e6 rad). On the M4F (soft-float `f64`,
//! `cargo xtask bench-m4`) a `sin_cos` costs about 5 100 instructions at
//! 1–100 rad (libm 4 900–5 600), 160 at 0 and 1 400 at π (libm 86 and
//! 6 500).
//!
//! Method: `x = k·π/2 + r` with `k` the nearest integer to `x·2/π` and
//! `π/2` split in three parts (Cody–Waite): the first two have 33
//! significant bits, so `k·part` is exact for |k| < 2²⁰ and `x − k·hi` is
//! exact; `r` is carried as a pair `hi + lo`. Then `sin r` and `cos r` on
//! |r| ≤ π/4 by polynomials in `z = r²`, and the quadrant `k mod 4` picks
//! ±sin or ±cos.
//!
//! The polynomials are Chebyshev fits of degree 5 in `z` over
//! `[0, 1.01·(π/4)²]` (60-digit arithmetic, coefficients rounded to
//! `f64`), made with mpmath:
//!
//! ```text
//! X = (pi/4)**2 * 1.01
//! chebyfit(lambda z: (sin(sqrt(z)) - sqrt(z)) / sqrt(z)**3, [0, X], 6)  # sin: rel. error 1.5e-17
//! chebyfit(lambda z: (cos(sqrt(z)) - 1 + z/2) / z**2, [0, X], 6)        # cos: rel. error 7e-19
//! ```
//!
//! Accuracy (tests, against libm on the host): within 2 ulp for
//! |x| ≤ 100, within 1e-15 absolute for |x| ≤ 1e4; `sin 0 = 0`,
//! `cos 0 = 1`, `sin(π/2) = 1`. NaN and ±∞ give NaN. Finite |x| above
//! [`EXACT_REDUCTION_MAX`] still give a finite value in [−1, 1], but the
//! reduction is no longer exact (error growing like |x|·2⁻⁵³: meaningless
//! beyond about 1e15 rad).

/// π/2, first part: 33 significant bits (`0x1.921fb544p0`).
const PIO2_HI: f64 = 1.570_796_326_734_125_6;
/// π/2, second part: 33 significant bits (`0x1.0b4611a6p-34`).
const PIO2_MID: f64 = 6.077_100_506_303_966e-11;
/// π/2, third part: the rest rounded to `f64`; `PIO2_HI + PIO2_MID +
/// PIO2_LO` is π/2 within 1.1e-37.
const PIO2_LO: f64 = 2.022_266_248_795_950_6e-21;

/// Largest |x|, rad, whose reduction is exact: `k = round(x·2/π)` stays
/// below 2²⁰, so `k·PIO2_HI` and `k·PIO2_MID` are exact.
pub const EXACT_REDUCTION_MAX: f64 = 1.6e6;

/// The sign bit of an `f64`.
const SIGN_BIT: u64 = 1 << 63;

/// 2⁵¹: from here on every `f64` is an integer or half-integer.
const TWO_POW_51: f64 = 2_251_799_813_685_248.0;

/// 2⁻²⁷: below this |r|, sin r = r and cos r = 1 in `f64`.
const TINY: f64 = 7.450_580_596_923_828e-9;

/// 1.5·2⁵²: adding and subtracting it rounds an `f64` of magnitude below
/// 2⁵¹ to the nearest integer (ties to even).
const ROUND_TO_INT: f64 = 6_755_399_441_055_744.0;

/// Coefficients of `(sin r − r)/r³` in `z = r²`, from `z⁰` up.
const SIN_Z: [f64; 6] = [
    -0.166_666_666_666_666_66,
    0.008_333_333_333_330_827,
    -0.000_198_412_698_365_757_1,
    2.755_731_600_817_155e-6,
    -2.505_111_227_257_324_3e-8,
    1.591_672_619_388_933_6e-10,
];

/// Coefficients of `(cos r − 1 + r²/2)/r⁴` in `z = r²`, from `z⁰` up.
const COS_Z: [f64; 6] = [
    0.041_666_666_666_666_664,
    -0.001_388_888_888_888_732_2,
    2.480_158_729_865_129_2e-5,
    -2.755_731_721_268_659e-7,
    2.087_613_402_409_014_5e-9,
    -1.138_175_465_366_293_7e-11,
];

/// Sine of `x` (radians). See the module documentation for accuracy.
#[inline(never)]
pub fn sin(x: f64) -> f64 {
    sin_of(&reduce(x), 0)
}

/// Cosine of `x` (radians). See the module documentation for accuracy.
#[inline(never)]
pub fn cos(x: f64) -> f64 {
    sin_of(&reduce(x), 1)
}

/// `(sin x, cos x)` with one argument reduction; each equal to [`sin`]
/// and [`cos`] bit for bit.
#[inline(never)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let r = reduce(x);
    (sin_of(&r, 0), sin_of(&r, 1))
}

/// Arccosine of `x`, rad in [0, π]; NaN for NaN and outside [−1, 1].
///
/// As `atan2(√((1 − x)(1 + x)), x)` with libm's `atan2` and `sqrt`,
/// which the firmware links anyway; libm's own `acos` is 700 B of flash.
/// Within 2 ulp of libm's `acos` (tests): `1 − x` is exact near 1, where
/// the angle is small and every bit counts.
#[inline(never)]
pub fn acos(x: f64) -> f64 {
    libm::atan2(libm::sqrt((1.0 - x) * (1.0 + x)), x)
}

/// `x = quadrant·π/2 + hi + lo` with |hi + lo| ≤ π/4 (a little more at
/// the rounding boundaries) and `lo` a correction far below `hi`'s last
/// bit; only `quadrant mod 4` matters.
struct Reduced {
    quadrant: i32,
    hi: f64,
    lo: f64,
}

/// sin(x + `quarter_turns`·π/2) of a reduced `x`: sin or cos of the
/// remainder, with the quadrant's sign.
#[inline(never)]
fn sin_of(r: &Reduced, quarter_turns: i32) -> f64 {
    let quadrant = r.quadrant.wrapping_add(quarter_turns);
    let sine = quadrant & 1 == 0;
    let v = if r.hi.to_bits() & !SIGN_BIT < TINY.to_bits() {
        // |r| < 2⁻²⁷: sin r rounds to r and cos r to 1 (the next terms
        // are below half an ulp). Saves the polynomials at 0 and at
        // exact multiples of π/2 (arcs often start there).
        if sine { r.hi + r.lo } else { 1.0 }
    } else if sine {
        sin_kernel(r.hi, r.lo)
    } else {
        cos_kernel(r.hi, r.lo)
    };
    if quadrant & 2 == 0 { v } else { -v }
}

/// The argument reduction (see the module documentation). NaN and ±∞
/// give a NaN remainder. For finite |x| above [`EXACT_REDUCTION_MAX`] the
/// same steps are inexact; the remainder is then clamped to [−π/4, π/4]
/// so the result stays finite and within [−1, 1].
///
/// The magnitude tests compare bit patterns (for non-negative floats the
/// same order as the values, NaN above ∞): integer compares, where an
/// `f64` compare is a library call on the M4F.
#[inline(never)]
fn reduce(x: f64) -> Reduced {
    let magnitude = x.to_bits() & !SIGN_BIT;
    if magnitude <= core::f64::consts::FRAC_PI_4.to_bits() {
        return Reduced {
            quadrant: 0,
            hi: x,
            lo: 0.0,
        };
    }
    let n = x * core::f64::consts::FRAC_2_PI;
    // Below 2⁵¹ round with the 1.5·2⁵² shift; above, n is an integer
    // already (NaN and ±∞ pass through).
    let k = if n.to_bits() & !SIGN_BIT < TWO_POW_51.to_bits() {
        (n + ROUND_TO_INT) - ROUND_TO_INT
    } else {
        n
    };
    // Exact for |x| ≤ EXACT_REDUCTION_MAX: k·PIO2_HI has at most 53 bits
    // and lies within π/4 of x.
    let t = x - k * PIO2_HI;
    // Exact product; the difference's rounding error is recovered in lo.
    let w = k * PIO2_MID;
    let mut hi = t - w;
    let mut lo = ((t - hi) - w) - k * PIO2_LO;
    if magnitude > EXACT_REDUCTION_MAX.to_bits() {
        let quarter = core::f64::consts::FRAC_PI_4;
        hi = super::clamp(hi + lo, -quarter, quarter);
        lo = 0.0;
    }
    // `as i64` saturates beyond 2⁶³ (the quadrant is arbitrary there);
    // `as i32` keeps the low bits.
    Reduced {
        quadrant: k as i64 as i32,
        hi,
        lo,
    }
}

/// sin(hi + lo) for |hi + lo| ≲ π/4.
#[inline(always)]
fn sin_kernel(hi: f64, lo: f64) -> f64 {
    let z = hi * hi;
    let [s0, s1, s2, s3, s4, s5] = SIN_Z;
    let p = s0 + z * (s1 + z * (s2 + z * (s3 + z * (s4 + z * s5))));
    // sin(hi + lo) ≈ sin hi + lo·cos hi; lo·(cos hi − 1) is below 0.2 ulp.
    hi + (hi * z * p + lo)
}

/// cos(hi + lo) for |hi + lo| ≲ π/4.
#[inline(always)]
fn cos_kernel(hi: f64, lo: f64) -> f64 {
    let z = hi * hi;
    let [c0, c1, c2, c3, c4, c5] = COS_Z;
    let q = c0 + z * (c1 + z * (c2 + z * (c3 + z * (c4 + z * c5))));
    let half_z = 0.5 * z;
    let head = 1.0 - half_z;
    // (1 − head) − half_z: the rounding error of `head`, recovered exactly.
    let tail = ((1.0 - head) - half_z) + (z * z * q - hi * lo);
    head + tail
}

#[cfg(test)]
mod tests;
