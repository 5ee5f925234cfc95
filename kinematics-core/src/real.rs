//! [`Real`]: the two float types the galvo path is generic over.
//!
//! The gimbal geometry and the error model are `f64` only. The galvo
//! kinematics and DAC mapping run per sample (100 kHz) on a Cortex-M4F whose
//! FPU is single precision, so they are generic: `f64` is the reference,
//! `f32` the fast path, and tests hold them to each other.
//!
//! The `f32` path stays on the M4F's single-precision FPU: square root is
//! the `VSQRT.F32` instruction ([`sqrt_f32`]; libm's `sqrtf` is a software
//! routine there), float → integer goes straight through `VCVT`
//! ([`Real::trunc_to_u32`]) instead of via `f64`, and nothing here widens
//! to `f64` (every `f64` operation is a library call on the M4F).

use core::fmt::Debug;
use core::ops::{Add, Div, Mul, Neg, Sub};

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

/// `f32` or `f64`, with the `libm` functions the galvo path needs.
/// Sealed: only those two types implement it.
pub trait Real:
    sealed::Sealed
    + Copy
    + Debug
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// 0.
    const ZERO: Self;
    /// 0.5.
    const HALF: Self;
    /// 1.
    const ONE: Self;
    /// 2.
    const TWO: Self;
    /// π/2.
    const FRAC_PI_2: Self;
    /// Nearest value of this type to `v`.
    fn from_f64(v: f64) -> Self;
    /// Widened to `f64` (exact).
    fn to_f64(self) -> f64;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Tangent (radians).
    fn tan(self) -> Self;
    /// Arctangent (radians).
    fn atan(self) -> Self;
    /// Rounds half away from zero.
    fn round(self) -> Self;
    /// Toward zero to an integer, saturating at 0 and `u32::MAX` (NaN →
    /// 0): exactly what the M4F's `VCVT.U32.F32` does, so in `f32` it is
    /// that one instruction.
    fn trunc_to_u32(self) -> u32;
    /// The value of `v` (exact in both types).
    fn from_u16(v: u16) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// Neither NaN nor infinite.
    fn is_finite(self) -> bool;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const HALF: Self = 0.5;
    const ONE: Self = 1.0;
    const TWO: Self = 2.0;
    const FRAC_PI_2: Self = core::f32::consts::FRAC_PI_2;
    #[inline]
    fn from_f64(v: f64) -> Self {
        v as f32
    }
    #[inline]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    #[inline]
    fn sqrt(self) -> Self {
        sqrt_f32(self)
    }
    #[inline]
    fn tan(self) -> Self {
        libm::tanf(self)
    }
    #[inline]
    fn atan(self) -> Self {
        // libm's atanf computes in f32 (unlike its sinf/cosf).
        libm::atanf(self)
    }
    #[inline]
    fn round(self) -> Self {
        libm::roundf(self)
    }
    #[inline]
    fn trunc_to_u32(self) -> u32 {
        self as u32
    }
    #[inline]
    fn from_u16(v: u16) -> Self {
        Self::from(v)
    }
    #[inline]
    fn abs(self) -> Self {
        libm::fabsf(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const HALF: Self = 0.5;
    const ONE: Self = 1.0;
    const TWO: Self = 2.0;
    const FRAC_PI_2: Self = core::f64::consts::FRAC_PI_2;
    #[inline]
    fn from_f64(v: f64) -> Self {
        v
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline]
    fn sqrt(self) -> Self {
        libm::sqrt(self)
    }
    #[inline]
    fn tan(self) -> Self {
        libm::tan(self)
    }
    #[inline]
    fn atan(self) -> Self {
        libm::atan(self)
    }
    #[inline]
    fn round(self) -> Self {
        libm::round(self)
    }
    #[inline]
    fn trunc_to_u32(self) -> u32 {
        self as u32
    }
    #[inline]
    fn from_u16(v: u16) -> Self {
        Self::from(v)
    }
    #[inline]
    fn abs(self) -> Self {
        libm::fabs(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

/// Square root of an `f32`, correctly rounded (IEEE 754, as
/// `libm::sqrtf`; NaN for negative input).
///
/// On ARM with a hardware FPU (`eabihf`: the Cortex-M4F's FPv4-SP and
/// every other VFP has `VSQRT.F32`) this is that one instruction (14
/// cycles, not a ~130-instruction software routine); elsewhere it is
/// `libm::sqrtf`. The bench on the target (`cargo xtask bench-m4`) checks
/// the instruction against `libm::sqrtf` bit for bit.
#[inline]
pub fn sqrt_f32(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        vsqrt(x)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        libm::sqrtf(x)
    }
}

/// `VSQRT.F32`. On stable Rust `f32::sqrt` is not in `core`, the
/// intrinsic is unstable, and `asm!`'s FPU register class needs the `vfp2`
/// target feature (double precision), which the M4F's single-precision
/// FPU does not have. So the operands travel in core registers and the
/// instruction borrows `s0`, saving and restoring it: the compiler sees no
/// FPU register change.
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[inline]
#[allow(unsafe_code)]
fn vsqrt(x: f32) -> f32 {
    let bits: u32;
    // SAFETY: only the declared core registers change; `s0` is restored
    // before the block ends. No memory, no stack, no APSR flags (VSQRT
    // only sets FPSCR's cumulative exception bits, which nothing here
    // reads).
    unsafe {
        core::arch::asm!(
            "vmov {saved}, s0",
            "vmov s0, {x}",
            "vsqrt.f32 s0, s0",
            "vmov {root}, s0",
            "vmov s0, {saved}",
            x = in(reg) x.to_bits(),
            root = lateout(reg) bits,
            saved = out(reg) _,
            options(pure, nomem, nostack, preserves_flags),
        );
    }
    f32::from_bits(bits)
}

#[cfg(test)]
mod tests {
    use super::{Real, sqrt_f32};

    fn check<F: Real>() {
        assert_eq!(F::from_f64(2.5).round().to_f64(), 3.0);
        assert_eq!(F::from_f64(-2.5).round().to_f64(), -3.0);
        assert_eq!(F::from_f64(9.0).sqrt().to_f64(), 3.0);
        assert_eq!(F::from_f64(-4.0).abs().to_f64(), 4.0);
        assert!((F::ONE.atan().to_f64() - core::f64::consts::FRAC_PI_4).abs() < 1e-7);
        assert!((F::from_f64(core::f64::consts::FRAC_PI_4).tan().to_f64() - 1.0).abs() < 1e-6);
        assert!(!F::from_f64(f64::NAN).is_finite());
        assert!(!F::from_f64(f64::INFINITY).is_finite());
        assert!(F::HALF.is_finite());
        assert_eq!(F::from_f64(4095.9).trunc_to_u32(), 4095);
        assert_eq!(F::from_f64(-3.0).trunc_to_u32(), 0);
        assert_eq!(F::from_f64(1e12).trunc_to_u32(), u32::MAX);
        assert_eq!(F::from_f64(f64::NAN).trunc_to_u32(), 0);
        assert_eq!(F::from_u16(4095).to_f64(), 4095.0);
    }

    #[test]
    fn sqrt_f32_is_correctly_rounded() {
        // Against the f64 root rounded once to f32 (exact for f32 inputs:
        // f64 has more than 2·24 + 2 bits), over many binades.
        let mut x = 1.0e-30f32;
        while x < 1.0e30 {
            for k in 0..7u8 {
                let v = x * (1.0 + f32::from(k) * 0.137);
                assert_eq!(sqrt_f32(v), libm::sqrt(f64::from(v)) as f32, "{v}");
            }
            x *= 1.9;
        }
        assert_eq!(sqrt_f32(0.0), 0.0);
        assert_eq!(sqrt_f32(f32::INFINITY), f32::INFINITY);
        assert!(sqrt_f32(-1.0).is_nan());
    }

    #[test]
    fn both_types_round_half_away_and_compute() {
        check::<f32>();
        check::<f64>();
    }
}
