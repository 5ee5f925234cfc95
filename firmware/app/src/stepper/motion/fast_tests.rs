//! The single-precision piece count against the exact one.

use kinematics_core::frames::BoardPoint;
use kinematics_core::path::Rotation;
use proptest::prelude::*;

use super::super::super::{LINE_TOLERANCE_MM, MoveShape, StepperConfig};
use super::super::StepperMotion;
use super::super::curve::Curve;
use super::Joints32;

/// Configurations: the default, a board off-centre and rolled, reversed
/// and offset axes with tight limits.
fn config(variant: usize) -> StepperConfig {
    let mut c = StepperConfig::default();
    match variant {
        1 => {
            let frame = &mut c.gimbal.geometry.frame;
            frame.x_offset_cm = 3.0;
            frame.y_offset_cm = -2.0;
            frame.pose.roll_deg = 4.0;
            frame.pose.dz_cm = 1.5;
            frame.oq_cm = 18.0;
        }
        2 => {
            c.direction[1] = kinematics_core::servo::Direction::Reversed;
            c.zero_deg = [1.5, -2.0];
            c.min_deg = [-20.0, -12.0];
            c.max_deg = [15.0, 25.0];
        }
        _ => {}
    }
    c
}

fn curve(f: [f64; 4], arc: Option<(f64, f64, bool)>) -> Curve {
    let from = BoardPoint::new(f[0] * 15.0, f[1] * 10.0);
    match arc {
        None => Curve::of(
            from,
            BoardPoint::new(f[2] * 15.0, f[3] * 10.0),
            MoveShape::Line,
        ),
        Some((r, a, cw)) => {
            let r = r * 10.0;
            let centre = BoardPoint::new(from.x_cm - r * a.cos(), from.y_cm - r * a.sin());
            let b = a + f[2] * 10.0;
            let to = BoardPoint::new(centre.x_cm + r * b.cos(), centre.y_cm + r * b.sin());
            let rotation = if cw { Rotation::Cw } else { Rotation::Ccw };
            Curve::of(from, to, MoveShape::Arc { centre, rotation })
        }
    }
    .expect("a line or an arc")
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn a_count_taken_here_is_the_exact_one(
        variant in 0..3usize,
        f in [-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64],
        arc in prop::option::of((0.02..1.0f64, -3.2..3.2f64, any::<bool>())),
    ) {
        let c = config(variant);
        let motion = StepperMotion::new(c).expect("a valid config");
        let joints = Joints32::of(&c.gimbal, c.min_deg, c.max_deg).expect("the exact model with OL = 0");
        let curve = curve(f, arc);
        let exact = motion.pieces_exactly(curve);
        prop_assert_eq!(motion.pieces_for(curve), exact);
        match joints.pieces(curve.shape(), curve.fewest_pieces(), LINE_TOLERANCE_MM, 4096, &|_, _| None) {
            Some(n) => {
                prop_assert_eq!(exact, Ok(n));
                prop_assert_eq!(motion.pieces_for(curve), Ok(n));
            }
            None => prop_assert_eq!(motion.pieces_for(curve), exact),
        }
    }
}

#[test]
fn most_counts_are_taken_here() {
    let c = config(0);
    let motion = StepperMotion::new(c).expect("a valid config");
    let joints =
        Joints32::of(&c.gimbal, c.min_deg, c.max_deg).expect("the exact model with OL = 0");
    let (mut sure, mut same) = (0, 0);
    for i in 0..200 {
        let t = f64::from(i) / 200.0;
        let f = [t - 0.5, 0.3 - t * 0.4, 0.5 - t, t * 0.6 - 0.2];
        let arc = (i % 2 == 0).then_some((0.1 + t * 0.5, t * 6.0 - 3.0, i % 4 == 0));
        let curve = curve(f, arc);
        if let Some(n) = joints.pieces(
            curve.shape(),
            curve.fewest_pieces(),
            LINE_TOLERANCE_MM,
            4096,
            &|_, _| None,
        ) {
            sure += 1;
            same += u32::from(motion.pieces_exactly(curve) == Ok(n));
        }
    }
    assert!(sure >= 190, "{sure}");
    assert_eq!(same, sure);
}

#[test]
fn the_seed_model_or_an_offset_laser_is_left_to_the_exact_count() {
    let mut c = StepperConfig::default();
    c.gimbal.geometry.ol_cm = 1.0;
    assert!(Joints32::of(&c.gimbal, c.min_deg, c.max_deg).is_none());
    let mut c = StepperConfig::default();
    c.gimbal.model = kinematics_core::gimbal::GimbalModel::Seed;
    assert!(Joints32::of(&c.gimbal, c.min_deg, c.max_deg).is_none());
}

#[test]
fn a_piece_too_close_to_call_is_decided_through_f64() {
    // One piece deviates 0.0495 mm (f32 and f64 agree to 1e-5 mm): within
    // 2 % of the 0.05 mm tolerance; two pieces deviate more (0.092 mm).
    let c = config(0);
    let motion = StepperMotion::new(c).expect("a valid config");
    let joints =
        Joints32::of(&c.gimbal, c.min_deg, c.max_deg).expect("the exact model with OL = 0");
    let f = [
        0.6658756102656522,
        0.6622165302648008,
        0.4960672632971193,
        -0.547674805155678,
    ];
    let curve = curve(f, None);
    let undecided = joints.pieces(
        curve.shape(),
        curve.fewest_pieces(),
        LINE_TOLERANCE_MM,
        4096,
        &|_, _| None,
    );
    assert_eq!(undecided, None);
    assert_eq!(motion.pieces_exactly(curve), Ok(1));
    assert_eq!(motion.pieces_for(curve), Ok(1));
}
