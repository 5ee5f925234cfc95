//! The core's event → action contract, one scenario each.

extern crate std;

use std::vec;
use std::vec::Vec;

use embassy_time::Instant;

use super::{Action, Core, Event, Inputs, Line};
use crate::command::Command;
use crate::domain::{Actuator, GridPattern, Pattern, PointCm};
use crate::galvo::{GALVO_REQUEST_DEPTH, GalvoRequest};
use crate::sequencer::LaserEvent;
use crate::servo::task::{ServoOutcome, ServoRequest};
use crate::settings::{JumpPlanner, LaserMode};
use crate::status::{Activity, Phase};
use crate::text::reply_text;

/// Whether a galvo loop serves the link.
const GALVO: bool = true;
const NO_GALVO: bool = false;

use crate::sequencer::gcode::tests::READINGS;

fn on_with(core: &mut Core, ms: u64, galvo: bool, event: Event) -> Vec<Action> {
    let inputs = Inputs {
        now: Instant::from_millis(ms),
        galvo_room: galvo.then_some(GALVO_REQUEST_DEPTH),
        // A host board: bisection allowed (refused on the M4: `planner_seed_*`).
        galvo_bisection: galvo,
        stepper_attached: galvo,
    };
    let mut out = Vec::new();
    core.on(inputs, event, &mut out);
    out
}

fn on(core: &mut Core, ms: u64, event: Event) -> Vec<Action> {
    on_with(core, ms, NO_GALVO, event)
}

fn command(core: &mut Core, ms: u64, command: Command, galvo: bool) -> Vec<Action> {
    let readings = READINGS;
    on_with(core, ms, galvo, Event::Command { command, readings })
}

fn move_seq(actions: &[Action]) -> Option<u32> {
    actions.iter().find_map(|a| match a {
        Action::Servo(ServoRequest::Move { seq, .. }) => Some(*seq),
        _ => None,
    })
}

fn error(text: &str) -> Action {
    Action::Line(Line::Error(reply_text(format_args!("{text}"))))
}

#[test]
fn a_goto_lights_after_the_arrival_holds_and_a_stop_darkens_everything() {
    let mut core = Core::new(Instant::from_millis(0));
    let goto = Command::Goto(PointCm {
        x_cm: 0.0,
        y_cm: 0.0,
    });
    let started = command(&mut core, 10, goto, NO_GALVO);
    assert_eq!(started[0], Action::Note(LaserEvent::RunStarted));
    assert_eq!(started[1], Action::CloseGate);
    assert_eq!(started[2], Action::Galvo(GalvoRequest::Stop));
    assert_eq!(started.last(), Some(&Action::Line(Line::Ok)));
    assert_eq!(core.status().phase, Some(Phase::Approaching));
    assert!(!core.laser_on(), "travel to the target is dark");

    let seq = move_seq(&started).expect("a servo move");
    let arrived = ServoOutcome::Arrived {
        seq,
        yaw_tenths: 0,
        pitch_tenths: 0,
    };
    let lit = on(&mut core, 500, Event::Servo(arrived));
    assert!(lit.contains(&Action::GimbalLaser(true)));
    assert_eq!(core.status().phase, Some(Phase::Dwelling));
    let deadline = core.dwell_deadline().expect("a dwell");
    assert!(deadline > Instant::from_millis(500));

    on(&mut core, deadline.as_millis(), Event::DwellEnded);
    assert_eq!(core.status().phase, Some(Phase::Holding));
    assert_eq!(core.dwell_deadline(), None);
    assert!(core.laser_on());

    let stopped = command(&mut core, 2_000, Command::Stop, NO_GALVO);
    assert_eq!(
        stopped,
        vec![
            Action::Note(LaserEvent::Stopped {
                why: "stop command"
            }),
            Action::CloseGate,
            Action::Galvo(GalvoRequest::Stop),
            Action::Line(Line::Ok),
            Action::GimbalLaser(false),
        ]
    );
    assert_eq!(core.status().activity, Activity::Idle);
}

#[test]
fn galvo_commands_are_refused_while_no_galvo_loop_serves_the_link() {
    let mut core = Core::new(Instant::from_millis(0));
    let no_galvo = error("this build has no galvo output");
    for c in [
        Command::Target(Actuator::Galvo),
        Command::Target(Actuator::Both),
        Command::GalvoStatus,
    ] {
        assert_eq!(command(&mut core, 1, c, NO_GALVO), vec![no_galvo.clone()]);
    }
    let gimbal = command(&mut core, 1, Command::Target(Actuator::Gimbal), NO_GALVO);
    assert_eq!(gimbal.last(), Some(&Action::Line(Line::Ok)));
    let galvo = command(&mut core, 1, Command::Target(Actuator::Galvo), GALVO);
    assert!(galvo.iter().any(|a| matches!(a, Action::ConfigureGalvo(_))));
    assert_eq!(galvo.last(), Some(&Action::Line(Line::Ok)));
}

#[test]
fn planner_seed_is_refused_where_the_board_cannot_afford_bisection() {
    let mut core = Core::new(Instant::from_millis(0));
    let seed = Command::Planner(JumpPlanner::Seed);
    let on_board = |core: &mut Core, command, bisection| {
        let inputs = Inputs {
            now: Instant::from_millis(1),
            galvo_room: Some(GALVO_REQUEST_DEPTH),
            galvo_bisection: bisection,
            stepper_attached: false,
        };
        let mut out = Vec::new();
        let readings = READINGS;
        core.on(inputs, Event::Command { command, readings }, &mut out);
        out
    };
    // The STM32 (an M4: 12-58 ms per axis): refused, nothing changes.
    let refused = on_board(&mut core, seed, false);
    assert_eq!(
        refused,
        vec![error(
            "planner seed does not fit this board (bisection: 12-58 ms per jump axis); \
             use planner optimal"
        )]
    );
    assert_eq!(core.settings.galvo.planner, JumpPlanner::Optimal);
    // `planner optimal` still works there; the simulator takes seed.
    let optimal = on_board(&mut core, Command::Planner(JumpPlanner::Optimal), false);
    assert_eq!(optimal.last(), Some(&Action::Line(Line::Ok)));
    let taken = on_board(&mut core, seed, true);
    assert!(taken.iter().any(|a| matches!(
        a,
        Action::ConfigureGalvo(c) if matches!(c.method, galvo_planner::Method::Bisection(_))
    )));
    assert_eq!(core.settings.galvo.planner, JumpPlanner::Seed);
}

#[test]
fn galvo_status_reports_the_measured_worst_refill_only_where_measured() {
    let mut core = Core::new(Instant::from_millis(0));
    let data = |actions: &[Action]| -> Vec<std::string::String> {
        actions
            .iter()
            .filter_map(|a| match a {
                Action::Line(Line::Data(text)) => Some(std::string::String::from(text.as_str())),
                _ => None,
            })
            .collect()
    };
    let unmeasured = command(&mut core, 1, Command::GalvoStatus, GALVO);
    assert!(!data(&unmeasured).iter().any(|l| l.contains("refill")));
    let mut readings = READINGS;
    // 20 160 cycles at 168 MHz = 120 us of a 1280 us half (128 samples at 10 us).
    readings.galvo.refill = Some(crate::galvo::RefillTime {
        cycles: 20_160,
        cpu_hz: 168_000_000,
        window_cycles: 215_040,
    });
    let command = Command::GalvoStatus;
    let measured = on_with(&mut core, 1, GALVO, Event::Command { command, readings });
    assert!(
        data(&measured)
            .contains(&"worst refill: 20160 cycles = 120 us, 9 % of the 1280 us half".into()),
        "{measured:?}"
    );
}

#[test]
fn a_pattern_check_yields_between_steps_and_replies_once_at_its_end() {
    let mut core = Core::new(Instant::from_millis(0));
    let pattern = Command::Pattern {
        pattern: Pattern::Grid(GridPattern::VisitAll),
        once: true,
    };
    let mut actions = command(&mut core, 1, pattern, NO_GALVO);
    let mut steps = 1;
    while actions.last() == Some(&Action::Yield) {
        assert!(
            !actions.iter().any(|a| matches!(a, Action::Line(_))),
            "no reply before the check ends"
        );
        assert_eq!(core.status().activity, Activity::Idle, "nothing starts yet");
        actions = on(&mut core, 1, Event::CheckStep);
        steps += 1;
    }
    assert!(steps > 1, "a check of many points takes several steps");
    assert_eq!(actions.last(), Some(&Action::Line(Line::Ok)));
    assert!(matches!(core.status().activity, Activity::Pattern(_)));
}

#[test]
fn a_save_replies_with_the_stores_answer_and_is_refused_while_running() {
    let mut core = Core::new(Instant::from_millis(0));
    assert_eq!(
        command(&mut core, 1, Command::Save, NO_GALVO),
        vec![Action::Save]
    );
    assert_eq!(
        on(&mut core, 2, Event::Saved(Err("flash full"))),
        vec![error("flash full")]
    );
    assert!(
        on(&mut core, 3, Event::Saved(Ok(()))).is_empty(),
        "no save pending"
    );
    let goto = Command::Goto(PointCm {
        x_cm: 0.0,
        y_cm: 0.0,
    });
    command(&mut core, 4, goto, NO_GALVO);
    assert_eq!(
        command(&mut core, 5, Command::Save, NO_GALVO),
        vec![error("stop the running pattern or goto before save")]
    );
}

#[test]
fn a_lost_gate_keeps_the_gimbal_laser_dark_until_the_next_run() {
    let mut core = Core::new(Instant::from_millis(0));
    command(&mut core, 0, Command::Laser(LaserMode::Auto), NO_GALVO);
    let goto = Command::Goto(PointCm {
        x_cm: 0.0,
        y_cm: 0.0,
    });
    let started = command(&mut core, 1, goto, NO_GALVO);
    let arrived = |seq| {
        Event::Servo(ServoOutcome::Arrived {
            seq,
            yaw_tenths: 0,
            pitch_tenths: 0,
        })
    };
    on(&mut core, 2, arrived(move_seq(&started).unwrap_or(0)));
    assert!(core.laser_on());
    assert_eq!(
        on(&mut core, 3, Event::GateLost),
        vec![Action::GimbalLaser(false)]
    );
    assert!(on(&mut core, 3_000, Event::DwellEnded).is_empty());
    assert!(!core.laser_on(), "dark while holding");
    let again = command(&mut core, 4_000, goto, NO_GALVO);
    on(&mut core, 4_500, arrived(move_seq(&again).unwrap_or(0)));
    assert!(core.laser_on(), "a new run lights again");
}

/// The servo move in `actions`: `(yaw, pitch)`, 0.1°.
fn move_tenths(actions: &[Action]) -> Option<(i16, i16)> {
    actions.iter().find_map(|a| match a {
        Action::Servo(ServoRequest::Move {
            yaw_tenths,
            pitch_tenths,
            ..
        }) => Some((*yaw_tenths, *pitch_tenths)),
        _ => None,
    })
}

#[test]
fn the_geometry_follows_every_change_of_the_settings_and_the_model() {
    use crate::domain::AimModel;
    use crate::settings::{Settings, find_param};

    let param = |name| find_param(name).expect("a parameter");
    let point = PointCm {
        x_cm: 8.0,
        y_cm: 3.0,
    };
    let wire = |settings: &Settings, model| {
        let aim = settings.aimer(model).aim(point).expect("reachable");
        (aim.yaw_wire, aim.pitch_wire)
    };
    let mut core = Core::new(Instant::from_millis(0));
    let set = |core: &mut Core, name, value| {
        let param = param(name);
        command(core, 1, Command::Set { param, value }, NO_GALVO)
    };
    assert_eq!(
        set(&mut core, "yaw.zero_deg", 10.0).last(),
        Some(&Action::Line(Line::Ok))
    );
    let mut turned = Settings::default();
    turned.yaw.zero_deg = 10.0;
    let goto = command(&mut core, 2, Command::Goto(point), NO_GALVO);
    assert_eq!(move_tenths(&goto), Some(wire(&turned, AimModel::Exact)));
    assert_ne!(
        wire(&turned, AimModel::Exact),
        wire(&Settings::default(), AimModel::Exact)
    );

    let seed = command(&mut core, 3, Command::Model(AimModel::Seed), NO_GALVO);
    assert_eq!(move_tenths(&seed), Some(wire(&turned, AimModel::Seed)));

    // A refused value changes nothing, the geometry included.
    let refused = set(&mut core, "pitch.max_deg", 1.0);
    assert!(
        matches!(refused.last(), Some(Action::Line(Line::Error(_)))),
        "{refused:?}"
    );
    let again = command(&mut core, 4, Command::Goto(point), NO_GALVO);
    assert_eq!(move_tenths(&again), Some(wire(&turned, AimModel::Seed)));
    let exact = command(&mut core, 5, Command::Model(AimModel::Exact), NO_GALVO);
    assert_eq!(move_tenths(&exact), Some(wire(&turned, AimModel::Exact)));
}
