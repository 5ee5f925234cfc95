//! Galvo IK and DAC mapping per sample, gimbal IK and compensation per
//! point.

use core::hint::black_box;

use kinematics_core::{BoardPoint, DacAxis, ErrorModel, Galvo, Gimbal, MirrorAngles, PointMm};

use crate::harness::Bench;

/// Galvo IK and DAC mapping per sample, gimbal IK and compensation per
/// point.
pub fn kinematics(b: &mut Bench) {
    galvo_mapping(b);
    gimbal(b);
}

/// Galvo IK and DAC mapping per sample, f32 and f64.
#[inline(always)]
fn galvo_mapping(b: &mut Bench) {
    let g32 = Galvo::<f32>::default();
    let g64 = Galvo::<f64>::default();
    const N: u32 = 1000;
    // Points spread over the field, varied per call so nothing is hoisted.
    let p32 = |i: u32| {
        let t = (i % 97) as f32;
        PointMm::new(-150.0 + 3.1 * t, 120.0 - 2.4 * t)
    };
    b.repeat("galvo.ik.f32", N, {
        let mut i = 0;
        move || {
            i += 1;
            g32.geometry.ik(black_box(p32(i)))
        }
    });
    b.repeat("galvo.board_to_codes.f32", N, {
        let mut i = 0;
        move || {
            i += 1;
            g32.board_to_codes(black_box(p32(i)))
        }
    });
    let map = match kinematics_core::SampleMap::new(&g32) {
        Ok(m) => m,
        Err(e) => return b.fail("galvo.sample_map", e),
    };
    b.repeat("galvo.sample_map.board_to_codes", N, {
        let mut i = 0;
        move || {
            i += 1;
            let p = black_box(p32(i));
            map.board_to_codes(p.x_mm, p.y_mm)
        }
    });
    b.repeat("galvo.sample_map.angles_to_codes", N, {
        let mut i = 0u32;
        move || {
            i += 1;
            let t = (i % 89) as f32 * 0.004 - 0.18;
            map.angles_to_codes(black_box(t), black_box(-t))
        }
    });
    b.repeat("galvo.angles_to_codes.f32", N, {
        let mut i = 0u32;
        move || {
            i += 1;
            let t = (i % 89) as f32 * 0.004 - 0.18;
            g32.angles_to_codes(black_box(MirrorAngles {
                x_rad: t,
                y_rad: -t,
            }))
        }
    });
    b.repeat("galvo.board_to_codes.f64", N, {
        let mut i = 0;
        move || {
            i += 1;
            let p = p32(i);
            g64.board_to_codes(black_box(PointMm::new(
                f64::from(p.x_mm),
                f64::from(p.y_mm),
            )))
        }
    });
    let dac = DacAxis::<f32>::default();
    b.repeat("dac.angle_to_code.f32", N, {
        let mut i = 0u32;
        move || {
            i += 1;
            dac.angle_to_code(black_box((i % 89) as f32 * 0.004 - 0.18))
        }
    });
}

/// Gimbal IK and error-model compensation per point.
#[inline(always)]
fn gimbal(b: &mut Bench) {
    let gimbal = Gimbal::default();
    b.repeat("gimbal.ik_wire", 100, {
        let mut i = 0u32;
        move || {
            i += 1;
            let t = f64::from(i % 13);
            gimbal.ik_wire(black_box(BoardPoint::new(-10.0 + 1.5 * t, 6.0 - t)))
        }
    });
    let model = ErrorModel::new(
        [0.12, 0.004, -0.002, 1e-4, -2e-5, 5e-5],
        [-0.08, -0.003, 0.005, -6e-5, 3e-5, 1e-4],
    );
    b.repeat("error_model.compensate", 100, {
        let mut i = 0u32;
        move || {
            i += 1;
            let t = f64::from(i % 13);
            model.compensate(black_box(PointMm::new(-100.0 + 15.0 * t, 60.0 - 10.0 * t)))
        }
    });
}
