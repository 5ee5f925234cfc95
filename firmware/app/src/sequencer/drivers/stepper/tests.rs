//! G-code on the stepper in the core: a resume while a hold still brakes,
//! the first lit move after power-up, a failed `$H`.

extern crate std;

use std::vec::Vec;

use embassy_time::Instant;

use crate::domain::Actuator;
use crate::grbl::realtime::Realtime;
use crate::sequencer::gcode::tests::{line, on, realtime, status, texts};
use crate::sequencer::machine::{Action, Core, Event, Line};
use crate::status::Activity;
use crate::stepper::{HomingFailure, MoveShape, StepperEvent, StepperRequest};

fn stepper_core() -> Core {
    let mut core = Core::new(Instant::from_millis(0));
    core.actuator = Actuator::Stepper;
    core
}

/// The stepper requests in `actions`.
fn requests(actions: &[Action]) -> Vec<StepperRequest> {
    actions
        .iter()
        .filter_map(|a| match a {
            Action::Stepper(r) => Some(*r),
            _ => None,
        })
        .collect()
}

/// The move requests in `actions`: (seq, shape, feed mm/s).
fn moves(actions: &[Action]) -> Vec<(u32, MoveShape, Option<f64>)> {
    requests(actions)
        .into_iter()
        .filter_map(|r| match r {
            StepperRequest::MoveTo {
                seq,
                shape,
                feed_mm_s,
                ..
            } => Some((seq, shape, feed_mm_s)),
            _ => None,
        })
        .collect()
}

fn stepper(core: &mut Core, ms: u64, event: StepperEvent) -> Vec<Action> {
    on(core, ms, Event::Stepper(event))
}

#[test]
fn a_resume_while_the_hold_still_brakes_goes_on_once_it_is_at_rest() {
    let mut core = stepper_core();
    let [(seq, MoveShape::Travel, None)] = moves(&line(&mut core, 1, "G0 X70 Y40"))[..] else {
        panic!("one travel");
    };
    let hold = requests(&realtime(&mut core, 10, Realtime::FeedHold));
    assert_eq!(hold, [StepperRequest::Hold]);
    // `~` 5 ms later, while it brakes: nothing to resume yet.
    let early = requests(&realtime(&mut core, 15, Realtime::CycleStart));
    assert!(!early.contains(&StepperRequest::Resume), "{early:?}");
    // At rest: it goes on with its moves.
    let at_rest = stepper(&mut core, 30, StepperEvent::Stopped { steps: [40, 20] });
    assert_eq!(requests(&at_rest), [StepperRequest::Resume]);
    assert!(status(&mut core, 31).starts_with("<Run|"));
    // The move arrives: the job is done, the next line runs.
    let steps = [1000, 500];
    stepper(&mut core, 900, StepperEvent::Arrived { seq, steps });
    assert!(status(&mut core, 901).starts_with("<Idle|"));
    assert_eq!(moves(&line(&mut core, 902, "G0 X0 Y0")).len(), 1);
}

#[test]
fn a_second_hold_while_it_still_brakes_after_a_resume_holds_again() {
    let mut core = stepper_core();
    line(&mut core, 1, "G0 X70 Y40");
    realtime(&mut core, 10, Realtime::FeedHold);
    realtime(&mut core, 15, Realtime::CycleStart);
    let again = requests(&realtime(&mut core, 16, Realtime::FeedHold));
    assert_eq!(again, [StepperRequest::Hold]);
    let at_rest = stepper(&mut core, 30, StepperEvent::Stopped { steps: [40, 20] });
    assert!(requests(&at_rest).is_empty());
    assert!(status(&mut core, 31).starts_with("<Hold:0|"));
    let resumed = requests(&realtime(&mut core, 40, Realtime::CycleStart));
    assert_eq!(resumed, [StepperRequest::Resume]);
}

#[test]
fn the_first_lit_move_after_power_up_is_a_line_at_its_feed_lit() {
    let mut core = stepper_core();
    line(&mut core, 1, "M3 S1000");
    let out = line(&mut core, 2, "G1 X20 F600");
    let [(_, MoveShape::Line, Some(feed))] = moves(&out)[..] else {
        panic!("one line: {:?}", moves(&out));
    };
    assert_eq!(feed, 10.0, "600 mm/min");
    assert!(
        core.laser_on(),
        "lit from its start: the position is counted"
    );
}

#[test]
fn a_failed_home_leaves_the_counted_position_in_mpos_and_status_says_homing() {
    let mut core = stepper_core();
    core.settings.stepper.pan.home_dir = 1.0;
    let out = line(&mut core, 1, "$H");
    assert!(requests(&out).contains(&StepperRequest::Home));
    assert_eq!(core.status().activity, Activity::Homing);
    assert!(status(&mut core, 2).starts_with("<Home|"));
    // A stop ended the seek at pan +16.9°.
    let steps = [300, 0];
    let why = HomingFailure::Interrupted;
    let out = stepper(&mut core, 7000, StepperEvent::HomingFailed { why, steps });
    assert!(
        texts(&out).iter().any(|t| t == "ALARM:6"),
        "{:?}",
        texts(&out)
    );
    assert_eq!(core.status().activity, Activity::Idle);
    let config = crate::sequencer::drivers::stepper::config(core.settings());
    let spot = config.gimbal.fk(config.joints_of(steps).unwrap()).unwrap();
    let report = status(&mut core, 7001);
    let mpos = std::format!("MPos:{:.3},{:.3},", spot.x_cm * 10.0, spot.y_cm * 10.0);
    assert!(
        report.starts_with("<Alarm|") && report.contains(&mpos),
        "{report} vs {mpos}"
    );
    // Unlocked, G0 X0 Y0 goes back from there.
    line(&mut core, 7002, "$X");
    assert_eq!(moves(&line(&mut core, 7003, "G0 X0 Y0")).len(), 1);
}

#[test]
fn the_rest_of_a_stop_from_before_the_job_does_not_lose_its_move() {
    let mut core = stepper_core();
    // `target stepper` (a stop) typed ahead of the line: the stepper's
    // rest report comes after the line's move was sent.
    let [(seq, MoveShape::Line, _)] = moves(&line(&mut core, 1, "G1 X20 F600"))[..] else {
        panic!("one line");
    };
    stepper(&mut core, 2, StepperEvent::Stopped { steps: [0, 0] });
    assert!(status(&mut core, 3).starts_with("<Run|"));
    let steps = [-81, 0];
    stepper(&mut core, 2000, StepperEvent::Arrived { seq, steps });
    let report = status(&mut core, 2001);
    assert!(report.starts_with("<Idle|MPos:20.000,0.000,"), "{report}");
}

#[test]
fn a_move_the_stepper_refuses_raises_a_soft_limit_alarm_and_ends_the_job() {
    let mut core = stepper_core();
    let [(seq, MoveShape::Line, _)] = moves(&line(&mut core, 1, "G1 X20 F600"))[..] else {
        panic!("one line");
    };
    let why = crate::stepper::StepperRefusal::Unreachable;
    let out = stepper(&mut core, 2, StepperEvent::Refused { seq, why });
    assert!(
        texts(&out).iter().any(|t| t == "ALARM:2"),
        "{:?}",
        texts(&out)
    );
    // A push message: not part of whatever command is in flight (the
    // PELCO port's quiet one would have kept it from the host).
    assert!(
        out.iter()
            .any(|a| matches!(a, Action::Line(Line::Push(t)) if t.as_str() == "ALARM:2")),
        "{out:?}"
    );
    assert!(status(&mut core, 3).starts_with("<Alarm|"));
    assert!(!core.laser_on());
}
