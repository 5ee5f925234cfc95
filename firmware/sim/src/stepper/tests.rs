use super::*;
use kinematics_core::frames::BoardPoint;
use kinematics_core::stepper::{Planner, SegmentPrep, SegmentQueue, StepGenerator, StepMove};

const TIMER_HZ: u32 = 1_000_000;
const PULSE_NS: u64 = 3_000;
const SETUP_NS: u64 = 6_000;

fn mv(steps: [i32; 2], rate: f64, accel: f64) -> StepMove {
    StepMove {
        steps,
        nominal_rate_steps_per_s: rate,
        accel_steps_per_s2: accel,
    }
}

/// Runs `moves` through the motion pipeline and plays each step event on
/// the drivers as the target does: DIR first, STEP `SETUP_NS` later, high
/// for `PULSE_NS`. Returns the end time, ns.
fn play(drivers: &mut PanTiltDrivers, moves: &[StepMove], start_ns: u64) -> u64 {
    play_until(drivers, moves, start_ns, usize::MAX)
}

/// As [`play`], halting the step generator after `halt_after` events.
fn play_until(
    drivers: &mut PanTiltDrivers,
    moves: &[StepMove],
    start_ns: u64,
    halt_after: usize,
) -> u64 {
    let mut planner: Planner<16> = Planner::new(2.0).unwrap();
    for m in moves {
        planner.push(m).unwrap();
    }
    let mut prep = SegmentPrep::new(TIMER_HZ, 0.0015).unwrap();
    let mut queue: SegmentQueue<4> = SegmentQueue::default();
    let mut generator = StepGenerator::new();
    let mut t = start_ns;
    for _ in 0..halt_after {
        prep.fill(&mut planner, &mut queue);
        let Some(tick) = generator.tick(&mut queue) else {
            return t;
        };
        emit(drivers, tick.step, tick.negative, t);
        t += u64::from(tick.period_ticks) * 1_000_000_000 / u64::from(TIMER_HZ);
    }
    generator.halt();
    t
}

fn emit(drivers: &mut PanTiltDrivers, step: [bool; 2], negative: [bool; 2], t: u64) {
    for axis in 0..2u8 {
        let i = usize::from(axis);
        drivers.edge(StepEdge {
            t_ns: t,
            axis,
            pin: StepPin::Dir,
            high: negative[i],
        });
        if step[i] {
            for (dt, high) in [(SETUP_NS, true), (SETUP_NS + PULSE_NS, false)] {
                drivers.edge(StepEdge {
                    t_ns: t + dt,
                    axis,
                    pin: StepPin::Step,
                    high,
                });
            }
        }
    }
}

fn drivers() -> PanTiltDrivers {
    PanTiltDrivers::new(DriverTiming::default(), MotorLimits::default())
}

#[test]
fn counts_steps_by_dir_with_clean_timing() {
    let mut d = drivers();
    let moves = [
        mv([3000, -1200], 20_000.0, 200_000.0),
        mv([-1000, 200], 20_000.0, 200_000.0),
    ];
    let end = play(&mut d, &moves, 0);
    d.axes.iter_mut().for_each(|a| a.settle(end + 300_000_000));
    assert_eq!(d.counted_steps(), [2000, -1000]);
    for a in &d.axes {
        assert_eq!(a.violations(), TimingViolations::default());
        assert!(a.stalls().is_empty(), "{:?}", a.stalls());
        assert_eq!(a.lost_steps(), 0);
    }
    assert!(!d.stalled());
    // The pan axis reached its cruise rate (dominant in the first move).
    let peak = d.axes[0].peak_rate_steps_per_s();
    assert!(peak > 19_000.0 && peak <= 20_000.0, "{peak}");
    let csv = d.edges_csv();
    assert!(csv.starts_with("t_ns,axis,pin,level\n"));
    // Each step is a rising and a falling STEP edge.
    assert_eq!(
        csv.lines().filter(|l| l.contains(",step,")).count(),
        2 * (3000 + 1200 + 1000 + 200)
    );
    assert!(d.report().contains("no stall"));
}

#[test]
fn pulse_timing_violations_are_counted() {
    let mut d = drivers();
    let a = &mut d.axes[0];
    // 1 µs high: too short; then low 1 µs: too short.
    a.set_step(true, 10_000);
    a.set_step(false, 11_000);
    a.set_step(true, 12_000);
    a.set_step(false, 20_000);
    // DIR 1 µs before the rising edge: too little setup.
    a.set_dir(true, 100_000);
    a.set_step(true, 101_000);
    // DIR changed while STEP is high.
    a.set_dir(false, 102_000);
    a.set_step(false, 110_000);
    let v = a.violations();
    assert_eq!(
        (v.short_high, v.short_low, v.dir_setup, v.dir_while_high),
        (1, 1, 1, 1)
    );
    assert_eq!(v.total(), 4);
    // +1, +1, −1 (DIR was high at the third rising edge).
    assert_eq!(a.counted_steps(), 1);
}

#[test]
fn too_aggressive_acceleration_stalls_and_the_report_says_so() {
    let limits = MotorLimits::default();
    let run = |accel: f64| {
        let mut d = drivers();
        let end = play(&mut d, &[mv([20_000, 0], 20_000.0, accel)], 0);
        d.axes[0].settle(end + 300_000_000);
        d
    };
    // A third of the motor's capability: follows, lag under a full step.
    let ok = run(limits.max_accel_steps_per_s2 / 3.0);
    assert!(!ok.stalled(), "{}", ok.report());
    assert!(
        ok.axes[0].peak_lag_steps() < 32.0,
        "{}",
        ok.axes[0].peak_lag_steps()
    );
    assert_eq!(ok.axes[0].lost_steps(), 0);
    // Three times it: the rotor falls two full steps behind and slips.
    let bad = run(limits.max_accel_steps_per_s2 * 3.0);
    assert!(bad.stalled());
    let stall = bad.axes[0].stalls()[0];
    assert!(stall.lag_steps < -80.0, "{stall:?}");
    // It settles whole electrical periods (4 full steps) off, or back in
    // place when the overshoot of the stop slipped it back as far.
    let lost = bad.axes[0].lost_steps();
    assert_eq!(lost % 128, 0, "{lost}");
    assert_eq!(bad.axes[0].counted_steps(), 20_000);
    let report = bad.report();
    assert!(
        report.contains("stepper pan") && report.contains("STALL"),
        "{report}"
    );
    assert!(
        report.contains("stepper tilt") && report.contains("no stall"),
        "{report}"
    );
}

#[test]
fn rate_beyond_the_motor_stalls() {
    let mut d = PanTiltDrivers::new(
        DriverTiming::default(),
        MotorLimits {
            max_rate_steps_per_s: 10_000.0,
            ..MotorLimits::default()
        },
    );
    let end = play(&mut d, &[mv([0, 8000], 15_000.0, 100_000.0)], 0);
    d.axes[1].settle(end + 300_000_000);
    assert!(!d.axes[1].stalls().is_empty());
    let lost = d.axes[1].lost_steps();
    assert!(lost != 0 && lost % 128 == 0, "{lost} {}", d.report());
}

/// Halting steps at once from speed: the rotor coasts; from a high rate
/// it runs past two full steps and slips.
#[test]
fn abrupt_halt_from_speed() {
    let halt_at = |rate: f64| {
        let mut d = drivers();
        // Cruising by event 3000 at ≤ 20 000 steps/s and 150 000 steps/s².
        let end = play_until(&mut d, &[mv([8000, 0], rate, 150_000.0)], 0, 3000);
        d.axes[0].settle(end + 300_000_000);
        assert_eq!(d.axes[0].counted_steps(), 3000);
        d
    };
    let slow = halt_at(2_000.0);
    assert!(!slow.stalled(), "{}", slow.report());
    assert_eq!(slow.axes[0].lost_steps(), 0);
    let fast = halt_at(20_000.0);
    assert!(fast.stalled(), "{}", fast.report());
    assert!(
        fast.axes[0].lost_steps() < 0,
        "overshoot: {}",
        fast.axes[0].lost_steps()
    );
}

#[test]
fn spot_from_counted_steps_through_the_exact_fk() {
    let g = StepperGeometry::default();
    assert_eq!(
        g.spot_cm([0, 0]).map(|p| (p.x_cm, p.y_cm)),
        Some((0.0, 0.0))
    );
    let target = BoardPoint {
        x_cm: 7.5,
        y_cm: -4.0,
    };
    let j = g.gimbal.ik(target).unwrap();
    let steps = [
        i64::from(g.axes[0].angle_to_steps(j.yaw_deg).unwrap()),
        i64::from(g.axes[1].angle_to_steps(j.pitch_deg).unwrap()),
    ];
    let spot = g.spot_cm(steps).unwrap();
    // Half a step (0.028°) at 25 cm is ≤ 0.13 mm per axis.
    let err_mm = 10.0 * (spot.x_cm - target.x_cm).hypot(spot.y_cm - target.y_cm);
    assert!(err_mm < 0.2, "{err_mm}");
    assert!(err_mm > 0.0);
    assert!(g.spot_cm([i64::MAX, 0]).is_none());
}

/// The simulated board's step: the STEP edges where the one-pulse timer
/// puts them (the DIR setup, then the pulse, in whole timer counts), and
/// an event that comes while a pulse still runs waits for its end before
/// DIR changes, as the STM32 board's does.
#[test]
fn the_sim_drive_pulses_as_the_one_pulse_timer_does() {
    use std::cell::RefCell;
    use std::rc::Rc;

    use laser_app::stepper::{DriverSignals, StepperDrive};

    crate::clock::reset(false);
    let drivers = Rc::new(RefCell::new(drivers()));
    let mut drive = SimStepperDrive::new(drivers.clone(), StepperGeometry::default(), [None; 2]);
    drive.set_signals(DriverSignals {
        pulse_ns: 2_500,
        dir_setup_ns: 5_000,
        enable_active_high: false,
    });
    crate::clock::advance_to(100);
    drive.step([true, false], [true, false]);
    // 2 µs later, before the pulse (5 µs setup + 2.5 µs) has ended.
    crate::clock::advance_to(102);
    drive.step([true, true], [false, false]);
    // No DIR change: the pulse one count (5.95 ns) after the start.
    crate::clock::advance_to(200);
    drive.step([false, true], [false, false]);
    let edges: Vec<_> = drivers
        .borrow()
        .edges
        .iter()
        .map(|e| (e.t_ns, e.axis, e.pin == StepPin::Step, e.high))
        .collect();
    let (dir, step) = (false, true);
    assert_eq!(
        edges,
        [
            (100_000, 0, dir, true),
            (105_000, 0, step, true),
            (107_500, 0, step, false),
            (107_500, 0, dir, false),
            (112_500, 0, step, true),
            (115_000, 0, step, false),
            (112_500, 1, step, true),
            (115_000, 1, step, false),
            (200_005, 1, step, true),
            (202_505, 1, step, false),
        ]
    );
    let drivers = drivers.borrow();
    for axis in &drivers.axes {
        assert_eq!(axis.violations().total(), 0);
    }
    assert_eq!(drivers.counted_steps(), [0, 2]);
}
