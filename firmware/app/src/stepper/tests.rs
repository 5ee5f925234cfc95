extern crate std;

use std::boxed::Box;
use std::vec::Vec;

use kinematics_core::frames::BoardPoint;
use kinematics_core::gimbal::JointAngles;

use super::*;

fn link() -> &'static StepperLink {
    Box::leak(Box::new(StepperLink::new()))
}

/// Runs the step timer synchronously until everything planned has
/// stepped; returns the position after every step event.
fn drain(motion: &mut StepperMotion, link: &StepperLink) -> Vec<[i32; 2]> {
    let mut positions = Vec::new();
    loop {
        while !link.with_queue(|q| q.is_full()) {
            let Some(seg) = motion.next_segment() else {
                break;
            };
            link.with_queue(|q| q.push_back(seg)).unwrap();
        }
        if link.step_tick().is_none() {
            if motion.is_planned_out() {
                return positions;
            }
            continue;
        }
        positions.push(link.position_steps());
    }
}

#[test]
fn seed_config_and_soft_limits() {
    let c = StepperConfig::default();
    assert_eq!(c.deg_per_step(), 0.05625);
    let j = JointAngles {
        yaw_deg: 9.0,
        pitch_deg: -4.5,
    };
    assert_eq!(c.steps_of(j), Ok([160, -80]));
    assert_eq!(c.joints_of([160, -80]), Some(j));
    let beyond = JointAngles {
        yaw_deg: 61.0,
        pitch_deg: 0.0,
    };
    assert_eq!(c.steps_of(beyond), Err(StepperRefusal::SoftLimit));
    // A zero offset and a reversed tilt.
    let c = StepperConfig {
        zero_deg: [1.125, 0.0],
        direction: [
            kinematics_core::servo::Direction::Normal,
            kinematics_core::servo::Direction::Reversed,
        ],
        ..c
    };
    assert_eq!(c.steps_of(j), Ok([140, 80]));
}

#[test]
fn move_to_a_point_ends_within_half_a_step() {
    let link = link();
    let config = StepperConfig::default();
    let mut motion = StepperMotion::new(config).unwrap();
    let target = BoardPoint::new(6.0, -3.5);
    motion.move_to(7, target, MoveShape::Travel, None).unwrap();
    let positions = drain(&mut motion, link);
    let end = *positions.last().unwrap();
    let j = config.gimbal.ik(target).unwrap();
    let reached = config.joints_of(end).unwrap();
    assert!((reached.yaw_deg - j.yaw_deg).abs() <= 0.05625 / 2.0 + 1e-9);
    assert!((reached.pitch_deg - j.pitch_deg).abs() <= 0.05625 / 2.0 + 1e-9);
    let spot = config.gimbal.fk(reached).unwrap();
    assert!(10.0 * (spot.x_cm - target.x_cm).hypot(spot.y_cm - target.y_cm) < 0.5);
    assert_eq!(motion.take_arrived(link.is_idle()), Some(7));
    assert_eq!(motion.take_arrived(true), None);
}

/// Largest spot displacement near `p` when each joint is off by up to
/// one step, mm: a piece's ends are rounded to whole steps (≤ ½ step
/// each) and Bresenham keeps within ½ step of the straight line between
/// them, so the spot may be off the piece's joint-space line by that.
fn one_step_mm(config: &StepperConfig, p: BoardPoint) -> f64 {
    let j = config.gimbal.ik(p).unwrap();
    let h = config.deg_per_step();
    [(h, h), (h, -h), (-h, h), (-h, -h)]
        .into_iter()
        .map(|(dy, dp)| {
            let moved = config
                .gimbal
                .fk(JointAngles {
                    yaw_deg: j.yaw_deg + dy,
                    pitch_deg: j.pitch_deg + dp,
                })
                .unwrap();
            10.0 * (moved.x_cm - p.x_cm).hypot(moved.y_cm - p.y_cm)
        })
        .fold(0.0, f64::max)
}

#[test]
fn board_line_stays_on_the_line() {
    let link = link();
    let config = StepperConfig::default();
    let mut motion = StepperMotion::new(config).unwrap();
    let (a, b) = (BoardPoint::new(-12.0, 10.0), BoardPoint::new(12.0, -8.0));
    motion.move_to(1, a, MoveShape::Travel, None).unwrap();
    drain(&mut motion, link);
    motion.move_to(2, b, MoveShape::Line, None).unwrap();
    let positions = drain(&mut motion, link);
    assert!(positions.len() > 500);
    let (dx, dy) = (b.x_cm - a.x_cm, b.y_cm - a.y_cm);
    let len = dx.hypot(dy);
    let mut worst = 0.0_f64;
    for steps in &positions {
        let spot = config.gimbal.fk(config.joints_of(*steps).unwrap()).unwrap();
        let off_mm = 10.0 * ((spot.x_cm - a.x_cm) * dy - (spot.y_cm - a.y_cm) * dx).abs() / len;
        let bound = LINE_TOLERANCE_MM + one_step_mm(&config, spot);
        assert!(off_mm <= bound, "{off_mm} mm > {bound} at {steps:?}");
        worst = worst.max(off_mm);
    }
    // The rounding to whole steps is most of it; without it the pieces
    // keep the path within the tolerance.
    assert!(worst > LINE_TOLERANCE_MM / 10.0);
    let end = config.steps_of(config.gimbal.ik(b).unwrap()).unwrap();
    assert_eq!(*positions.last().unwrap(), end);
}

#[test]
fn refusals_change_nothing() {
    let mut motion = StepperMotion::new(StepperConfig::default()).unwrap();
    // 60° of pan at 25 cm is 43 cm: beyond the soft limit.
    assert_eq!(
        motion.move_to(1, BoardPoint::new(50.0, 0.0), MoveShape::Travel, None),
        Err(StepperRefusal::SoftLimit)
    );
    assert!(motion.is_planned_out());
    assert_eq!(motion.planned_steps(), [0, 0]);
    let bad = StepperConfig {
        accel_deg_s2: f64::NAN,
        ..StepperConfig::default()
    };
    assert_eq!(motion.configure(bad), Err(StepperRefusal::BadConfig));
    assert_eq!(
        StepperMotion::new(bad).err(),
        Some(StepperRefusal::BadConfig)
    );
    assert_eq!(motion.config(), &StepperConfig::default());
}

#[test]
fn halt_drops_everything_prepared() {
    let link = link();
    let mut motion = StepperMotion::new(StepperConfig::default()).unwrap();
    motion
        .move_to(1, BoardPoint::new(10.0, 0.0), MoveShape::Travel, None)
        .unwrap();
    for _ in 0..200 {
        while !link.with_queue(|q| q.is_full()) {
            let Some(seg) = motion.next_segment() else {
                break;
            };
            link.with_queue(|q| q.push_back(seg)).unwrap();
        }
        link.step_tick().unwrap();
    }
    let at = link.position_steps();
    link.halt();
    assert_eq!(link.step_tick(), None);
    assert!(link.take_halt());
    assert!(link.is_idle());
    assert_eq!(link.step_tick(), None);
    assert_eq!(link.position_steps(), at);
    motion.rest_at(at);
    assert!(motion.is_planned_out());
    assert_eq!(motion.planned_steps(), at);
}

#[test]
fn stop_decelerates_to_rest_short_of_the_target() {
    let link = link();
    let config = StepperConfig::default();
    let mut motion = StepperMotion::new(config).unwrap();
    motion
        .move_to(1, BoardPoint::new(14.0, 0.0), MoveShape::Travel, None)
        .unwrap();
    for _ in 0..400 {
        while !link.with_queue(|q| q.is_full()) {
            let Some(seg) = motion.next_segment() else {
                break;
            };
            link.with_queue(|q| q.push_back(seg)).unwrap();
        }
        link.step_tick().unwrap();
    }
    link.with_queue_executing(|q, e| motion.stop(q, e));
    let positions = drain(&mut motion, link);
    let end = positions.last().unwrap()[0];
    let target = config
        .steps_of(config.gimbal.ik(BoardPoint::new(14.0, 0.0)).unwrap())
        .unwrap()[0];
    assert!(
        end.abs() > 400 && end.abs() < target.abs(),
        "{end} vs {target}"
    );
    assert_eq!(motion.take_arrived(true), None);
}

#[test]
fn board_circle_stays_on_the_circle() {
    let link = link();
    let config = StepperConfig::default();
    let mut motion = StepperMotion::new(config).unwrap();
    let centre = BoardPoint::new(2.0, -1.0);
    let top = BoardPoint::new(2.0, 7.0);
    motion.move_to(1, top, MoveShape::Travel, None).unwrap();
    drain(&mut motion, link);
    let shape = MoveShape::Arc {
        centre,
        rotation: kinematics_core::Rotation::Cw,
    };
    motion.move_to(2, top, shape, None).unwrap();
    let positions = drain(&mut motion, link);
    let mut angles = Vec::new();
    for steps in &positions {
        let spot = config.gimbal.fk(config.joints_of(*steps).unwrap()).unwrap();
        let (dx, dy) = (spot.x_cm - centre.x_cm, spot.y_cm - centre.y_cm);
        let off_mm = 10.0 * (dx.hypot(dy) - 8.0).abs();
        let bound = LINE_TOLERANCE_MM + one_step_mm(&config, spot);
        assert!(off_mm <= bound, "{off_mm} mm > {bound} at {steps:?}");
        angles.push(dy.atan2(dx));
    }
    // All the way round, clockwise: from the top through the right side.
    let right = angles.iter().position(|a| a.abs() < 0.05).unwrap();
    let left = angles
        .iter()
        .position(|a| (a.abs() - core::f64::consts::PI).abs() < 0.05)
        .unwrap();
    assert!(right < left);
    let start = config.steps_of(config.gimbal.ik(top).unwrap()).unwrap();
    assert_eq!(*positions.last().unwrap(), start);
}

/// Steps `motion` until everything planned has stepped; returns the
/// position after every step event and the time it took, s.
fn drain_timed(motion: &mut StepperMotion, link: &StepperLink) -> (Vec<[i32; 2]>, f64) {
    let (mut positions, mut ticks) = (Vec::new(), 0_u64);
    loop {
        while !link.with_queue(|q| q.is_full()) {
            let Some(seg) = motion.next_segment() else {
                break;
            };
            link.with_queue(|q| q.push_back(seg)).unwrap();
        }
        let Some(tick) = link.step_tick() else {
            if motion.is_planned_out() {
                return (positions, ticks as f64 / f64::from(STEP_TIMER_HZ));
            }
            continue;
        };
        ticks += u64::from(tick.period_ticks);
        positions.push(link.position_steps());
    }
}

#[test]
fn the_first_line_after_power_up_or_a_rest_is_cut_at_its_feed_from_the_counted_steps() {
    let config = StepperConfig::default();
    let at_steps = |p: BoardPoint| config.steps_of(config.gimbal.ik(p).unwrap()).unwrap();
    // Power-up (step 0), and a rest after a halt somewhere else.
    for rest in [None, Some(BoardPoint::new(-3.0, 2.0))] {
        let link = link();
        let mut motion = StepperMotion::new(config).unwrap();
        let start = rest.map_or([0, 0], at_steps);
        if rest.is_some() {
            // The steps halted there (the step timer counted them).
            link.set_position(0, start[0]);
            link.set_position(1, start[1]);
            motion.rest_at(start);
        }
        let from = config.gimbal.fk(config.joints_of(start).unwrap()).unwrap();
        let to = BoardPoint::new(from.x_cm + 2.0, from.y_cm);
        // 20 mm at 10 mm/s (G1 X20 F600): 2 s plus the ramps.
        motion.move_to(1, to, MoveShape::Line, Some(10.0)).unwrap();
        let (positions, seconds) = drain_timed(&mut motion, link);
        assert!(
            (2.0..2.2).contains(&seconds),
            "{rest:?}: 20 mm in {seconds} s"
        );
        for steps in &positions {
            let spot = config.gimbal.fk(config.joints_of(*steps).unwrap()).unwrap();
            let off_mm = 10.0 * (spot.y_cm - from.y_cm).abs();
            let bound = LINE_TOLERANCE_MM + one_step_mm(&config, spot);
            assert!(off_mm <= bound, "{rest:?}: {off_mm} mm off the line");
        }
    }
}

#[test]
fn no_line_is_cut_from_axes_wound_beyond_the_soft_limits() {
    let mut motion = StepperMotion::new(StepperConfig::default()).unwrap();
    // A failed homing seek left pan at 372° (6 613 steps).
    motion.rest_at([6613, 0]);
    let to = BoardPoint::new(1.0, 0.0);
    assert_eq!(
        motion.move_to(1, to, MoveShape::Line, Some(10.0)),
        Err(StepperRefusal::Unreachable)
    );
    // Travel back is allowed.
    assert_eq!(motion.move_to(2, to, MoveShape::Travel, None), Ok(true));
}
