use super::*;
use proptest::prelude::*;

const A: f64 = 500.0;

fn unit(angle_rad: f64) -> [f64; 2] {
    [libm::cos(angle_rad), libm::sin(angle_rad)]
}

/// Checks the planned queue: entries within their junction and nominal
/// limits, every profile reachable within its acceleration both ways,
/// the last block ending at rest.
fn check_plan<const N: usize>(p: &Lookahead<N>) -> Result<(), TestCaseError> {
    let eps = 1e-6;
    for i in 0..p.len() {
        let b = *p.block(i).unwrap();
        let exit = p.block(i + 1).map_or(0.0, |n| n.entry_speed);
        if i > 0 || p.frozen_head_entry.is_none() {
            prop_assert!(b.entry_speed <= b.max_entry_speed + eps);
        }
        prop_assert!(b.entry_speed <= b.nominal_speed + eps);
        prop_assert!(exit * exit <= b.entry_speed * b.entry_speed + 2.0 * b.accel * b.length + eps);
        prop_assert!(b.entry_speed * b.entry_speed <= exit * exit + 2.0 * b.accel * b.length + eps);
    }
    Ok(())
}

#[test]
fn junction_speed_limits() {
    let x = [1.0, 0.0];
    assert_eq!(junction_speed(x, [-1.0, 0.0], A, 0.01), 0.0);
    assert_eq!(junction_speed(x, x, A, 0.01), f64::INFINITY);
    let right = junction_speed(x, [0.0, 1.0], A, 0.01);
    let gentle = junction_speed(x, unit(0.05), A, 0.01);
    // v² = a·δ·sin(θ/2)/(1 − sin(θ/2)) with θ = 90°: sin 45°.
    let s = libm::sqrt(0.5);
    assert!((right - libm::sqrt(A * 0.01 * s / (1.0 - s))).abs() < 1e-9);
    assert!(gentle > 10.0 * right);
}

#[test]
fn refuses_bad_blocks_and_overflow() {
    let mut p = Lookahead::<2>::new(0.01).unwrap();
    assert_eq!(
        p.push(0.0, [[1.0, 0.0]; 2], 10.0, A),
        Err(LookaheadError::InvalidBlock)
    );
    assert_eq!(
        p.push(1.0, [[2.0, 0.0]; 2], 10.0, A),
        Err(LookaheadError::InvalidBlock)
    );
    assert_eq!(
        p.push(1.0, [[1.0, 0.0]; 2], f64::NAN, A),
        Err(LookaheadError::InvalidBlock)
    );
    p.push(1.0, [[1.0, 0.0]; 2], 10.0, A).unwrap();
    p.push(1.0, [[1.0, 0.0]; 2], 10.0, A).unwrap();
    assert_eq!(
        p.push(1.0, [[1.0, 0.0]; 2], 10.0, A),
        Err(LookaheadError::Full)
    );
    assert!(Lookahead::<2>::new(-1.0).is_err());
}

#[test]
fn collinear_blocks_cruise_through_and_a_break_stops() {
    let mut p = Lookahead::<8>::new(0.01).unwrap();
    for _ in 0..4 {
        p.push(100.0, [[1.0, 0.0]; 2], 50.0, A).unwrap();
    }
    assert_eq!(p.block(0).unwrap().entry_speed, 0.0);
    for i in 1..4 {
        assert_eq!(p.block(i).unwrap().entry_speed, 50.0);
    }
    p.break_junction();
    p.push(100.0, [[1.0, 0.0]; 2], 50.0, A).unwrap();
    assert_eq!(p.block(4).unwrap().entry_speed, 0.0);
}

/// A head frozen faster than the re-planned queue wants (a feed override
/// lowered the cruise of blocks the spot is already heading into at
/// speed): the blocks after it brake at the limit from that speed, above
/// their cruise where they must, never faster than the limit allows.
#[test]
fn a_fast_frozen_head_brakes_through_the_next_blocks_at_the_limit() {
    let mut p = Lookahead::<8>::new(0.01).unwrap();
    for _ in 0..3 {
        p.push(10.0, [[1.0, 0.0]; 2], 50.0, A).unwrap();
    }
    p.push(200.0, [[1.0, 0.0]; 2], 50.0, A).unwrap();
    p.limit_head_entry(200.0);
    let entries: [f64; 4] = core::array::from_fn(|i| p.block(i).unwrap().entry_speed);
    assert_eq!(entries[0], 200.0);
    // √(200² − 2·500·10) ≈ 173.2, then 141.4, then 100: above the cruise.
    for (i, want) in [(1, 173.205), (2, 141.421), (3, 100.0)] {
        assert!((entries[i] - want).abs() < 1e-3, "{i}: {entries:?}");
    }
    for i in 0..p.len() {
        let b = *p.block(i).unwrap();
        let exit = p.block(i + 1).map_or(0.0, |n| n.entry_speed);
        assert!(b.entry_speed * b.entry_speed <= exit * exit + 2.0 * A * b.length + 1e-6);
        assert!(exit * exit <= b.entry_speed * b.entry_speed + 2.0 * A * b.length + 1e-6);
    }
}

proptest! {
    /// Random blocks arrive while the head is taken now and then: every
    /// plan is feasible and ends at rest, and a taken head's successor
    /// keeps the entry it had (re-planning never raises a frozen head).
    #[test]
    fn plans_stay_feasible_as_blocks_arrive(
        moves in prop::collection::vec((0.05f64..50.0, -3.2f64..3.2, 1.0f64..200.0, 10.0f64..5000.0, 0u8..4), 1..60),
        deviation in 0.0f64..0.5,
    ) {
        let mut p = Lookahead::<6>::new(deviation).unwrap();
        let mut frozen: Option<f64> = None;
        for (length, angle, speed, accel, action) in moves {
            let take = p.is_full() || action == 0;
            if let Some(b) = take.then(|| p.pop()).flatten() {
                prop_assert_eq!(b.exit_speed, p.block(0).map_or(0.0, |n| n.entry_speed));
                frozen = p.block(0).map(|n| n.entry_speed);
            }
            if action == 1 {
                p.break_junction();
            }
            p.push(length, [unit(angle); 2], speed, accel).unwrap();
            if let (Some(f), Some(head)) = (frozen, p.block(0)) {
                prop_assert!(head.entry_speed <= f + 1e-9);
            }
            check_plan(&p)?;
            prop_assert_eq!(p.block(0).filter(|_| frozen.is_none()).map_or(0.0, |b| b.entry_speed), 0.0);
        }
    }

    /// Following a plan at a fixed period: the speed changes by at most
    /// a·dt per period, stays under the cruise speed, every block is
    /// covered in full and the motion ends at rest.
    #[test]
    fn the_cursor_follows_the_plan_within_its_limits(
        moves in prop::collection::vec((0.05f64..30.0, -3.2f64..3.2), 1..30),
        speed in 5.0f64..200.0,
        accel in 50.0f64..5000.0,
    ) {
        let dt = 0.02;
        let mut p = Lookahead::<64>::new(0.02).unwrap();
        let mut total = 0.0;
        for &(length, angle) in &moves {
            p.push(length, [unit(angle); 2], speed, accel).unwrap();
            total += length;
        }
        let mut cursor = SpeedCursor::start(p.pop().unwrap());
        let mut travelled = 0.0;
        let mut ticks = 0;
        loop {
            let before = cursor.speed;
            let over = cursor.advance(dt, 1.0, false);
            prop_assert!((cursor.speed - before).abs() <= accel * dt + 1e-9);
            prop_assert!(cursor.speed <= speed + 1e-9);
            ticks += 1;
            prop_assert!(ticks < 100_000);
            if over.is_some() {
                travelled += cursor.block.length;
                match p.pop() {
                    Some(next) => cursor.continue_into(next, 0.0),
                    None => break,
                }
            }
        }
        prop_assert!((travelled - total).abs() < 1e-9);
        // The last period brakes to (nearly) rest.
        prop_assert!(cursor.speed <= accel * dt + 1e-9);
    }
}

#[test]
fn a_hold_brakes_at_the_limit_and_resumes_from_rest() {
    let mut p = Lookahead::<4>::new(0.01).unwrap();
    p.push(1000.0, [[1.0, 0.0]; 2], 100.0, A).unwrap();
    let mut c = SpeedCursor::start(p.pop().unwrap());
    for _ in 0..50 {
        c.advance(0.02, 1.0, false);
    }
    assert!((c.speed - 100.0).abs() < 1e-9);
    let at = c.done;
    while !c.is_at_rest() {
        let before = c.speed;
        assert!(c.advance(0.02, 1.0, true).is_none());
        assert!(before - c.speed <= A * 0.02 + 1e-9);
    }
    // v²/2a = 10 mm of braking (within one period's travel).
    assert!((c.done - at - 10.0).abs() < 100.0 * 0.02);
    c.advance(0.02, 1.0, false);
    assert!(c.speed > 0.0 && c.speed <= A * 0.02 + 1e-9);
    // The override scales the cruise.
    for _ in 0..100 {
        c.advance(0.02, 0.5, false);
    }
    assert!((c.speed - 50.0).abs() < 1e-9);
}
