//! [`Real`]: the two float types the galvo path is generic over.
//!
//! The gimbal geometry and the error model are `f64` only. The galvo
//! kinematics and DAC mapping run per sample (100 kHz) on a Cortex-M4F whose
//! FPU is single precision, so they are generic: `f64` is the reference,
//! `f32` the fast path, and tests hold them to each other.

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
        libm::sqrtf(self)
    }
    #[inline]
    fn tan(self) -> Self {
        libm::tanf(self)
    }
    #[inline]
    fn atan(self) -> Self {
        libm::atanf(self)
    }
    #[inline]
    fn round(self) -> Self {
        libm::roundf(self)
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
    fn abs(self) -> Self {
        libm::fabs(self)
    }
    #[inline]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

#[cfg(test)]
mod tests {
    use super::Real;

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
    }

    #[test]
    fn both_types_round_half_away_and_compute() {
        check::<f32>();
        check::<f64>();
    }
}
