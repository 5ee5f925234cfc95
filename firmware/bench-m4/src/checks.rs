//! Checks only the target can make (FPU square root, f32 DAC mapping).

use core::fmt::Write;

use kinematics_core::DacAxis;

use crate::harness::Bench;

/// What only the target can check: the FPU square root (`VSQRT.F32` in
/// `asm!`, the host runs the libm fallback) against `libm::sqrtf` bit for
/// bit, and the f32 DAC conversion against the f64 one on the target's
/// code path.
pub fn self_checks(b: &mut Bench) {
    let mut checked = 0u32;
    let mut x = 1.0e-38f32;
    while x < 3.0e38 {
        for k in 0..16u8 {
            let v = x * (1.0 + f32::from(k) * 0.0625);
            let (hw, sw) = (kinematics_core::sqrt_f32(v), libm::sqrtf(v));
            if hw.to_bits() != sw.to_bits() {
                return b.fail("check.sqrt", (v, hw, sw));
            }
            checked += 1;
        }
        x *= 1.5;
    }
    for v in [0.0f32, -0.0, f32::INFINITY, f32::MIN_POSITIVE, 1.0e-45] {
        if kinematics_core::sqrt_f32(v).to_bits() != libm::sqrtf(v).to_bits() {
            return b.fail("check.sqrt", v);
        }
    }
    if !kinematics_core::sqrt_f32(-1.0).is_nan() {
        return b.fail("check.sqrt", -1.0f32);
    }
    let (d32, d64) = (DacAxis::<f32>::default(), DacAxis::<f64>::default());
    for i in 0..=20_000u32 {
        let theta = (i as f32 / 10_000.0 - 1.0) * 0.25;
        let (c32, c64) = (
            d32.angle_to_code(theta),
            d64.angle_to_code(f64::from(theta)),
        );
        let close = match (c32, c64) {
            (Ok(a), Ok(b)) => a.clamped == b.clamped && a.code.abs_diff(b.code) <= 1,
            _ => false,
        };
        if !close {
            return b.fail("check.dac", theta);
        }
    }
    let _ = writeln!(b.out, "check sqrt+dac ok {checked}");
    b.out.flush();
}
