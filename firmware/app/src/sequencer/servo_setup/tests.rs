extern crate std;
use std::vec::Vec;

use embassy_time::Instant;

use super::celsius;
use crate::command::{Command, ServoSetup};
use crate::sequencer::{Action, Core, Event, Inputs, Line};
use crate::servo::task::{BusEnd, BusJob, BusReport, ServoOutcome, ServoReading, ServoRequest};

use crate::sequencer::gcode::tests::READINGS;

fn on(core: &mut Core, event: Event) -> Vec<Action> {
    let inputs = Inputs {
        now: Instant::from_millis(10),
        galvo_room: None,
        galvo_bisection: false,
        stepper_attached: false,
    };
    let mut out = Vec::new();
    core.on(inputs, event, &mut out);
    out
}

fn servo(core: &mut Core, setup: ServoSetup) -> Vec<Action> {
    let command = Command::Servo(setup);
    on(
        core,
        Event::Command {
            command,
            readings: READINGS,
        },
    )
}

fn report(core: &mut Core, seq: u32, report: BusReport) -> Vec<Action> {
    on(core, Event::Servo(ServoOutcome::Bus { seq, report }))
}

/// The reply lines among `actions`, as text (`ok`, `error: …`, data).
fn lines(actions: &[Action]) -> Vec<std::string::String> {
    actions
        .iter()
        .filter_map(|a| match a {
            Action::Line(Line::Data(t)) => Some(std::string::ToString::to_string(t.as_str())),
            Action::Line(Line::Ok) => Some("ok".into()),
            Action::Line(Line::Error(t)) => Some(std::format!("error: {}", t.as_str())),
            _ => None,
        })
        .collect()
}

fn job(actions: &[Action]) -> Option<(u32, BusJob)> {
    actions.iter().find_map(|a| match a {
        Action::Servo(ServoRequest::Setup { seq, job }) => Some((*seq, *job)),
        _ => None,
    })
}

#[test]
fn a_scan_forwards_one_job_and_replies_with_its_lines_only() {
    let mut core = Core::new(Instant::from_millis(0));
    let started = servo(&mut core, ServoSetup::Scan);
    let Some((seq, BusJob::Scan)) = job(&started) else {
        panic!("{started:?}")
    };
    assert!(
        lines(&started).is_empty(),
        "no reply before the bus answers"
    );
    // Another job's report is not this reply's.
    assert!(report(&mut core, seq + 1, BusReport::Collision { id: 3 }).is_empty());
    let found = ServoReading {
        id: 0,
        angle_tenths: -113,
        voltage_mv: 7400,
        temperature_raw: 1854,
    };
    assert_eq!(
        lines(&report(&mut core, seq, BusReport::Servo(found))),
        ["servo 0: -11.3 deg, 7.40 V, 30 C"]
    );
    let end = BusReport::Done(BusEnd::Scanned {
        answering: 1,
        collisions: 0,
    });
    assert_eq!(
        lines(&report(&mut core, seq, end)),
        ["1 ids answering, 0 with colliding answers", "ok"]
    );
    // Closed: a late repeat adds nothing.
    assert!(report(&mut core, seq, end).is_empty());
}

#[test]
fn re_id_without_confirm_or_to_the_same_id_touches_no_bus() {
    let mut core = Core::new(Instant::from_millis(0));
    let dry = servo(
        &mut core,
        ServoSetup::SetId {
            id: 0,
            new_id: 1,
            confirmed: false,
        },
    );
    assert_eq!(job(&dry), None);
    assert_eq!(
        lines(&dry).last().map(std::string::String::as_str),
        Some("ok")
    );
    let same = servo(
        &mut core,
        ServoSetup::SetId {
            id: 2,
            new_id: 2,
            confirmed: true,
        },
    );
    assert_eq!(job(&same), None);
    assert_eq!(lines(&same), ["error: servo 2 has id 2 already"]);
    let real = servo(
        &mut core,
        ServoSetup::SetId {
            id: 0,
            new_id: 1,
            confirmed: true,
        },
    );
    assert!(matches!(
        job(&real),
        Some((_, BusJob::SetId { id: 0, new_id: 1 }))
    ));
}

#[test]
fn zero_writes_the_axis_parameter_of_that_id_within_its_range() {
    let mut core = Core::new(Instant::from_millis(0));
    assert_eq!(
        lines(&servo(&mut core, ServoSetup::Zero(9))),
        ["error: servo 9 is neither yaw.id nor pitch.id"]
    );
    let started = servo(&mut core, ServoSetup::Zero(1));
    let Some((seq, BusJob::ReadAngle { id: 1 })) = job(&started) else {
        panic!("{started:?}")
    };
    let angle = BusReport::Done(BusEnd::Angle { id: 1, tenths: 55 });
    assert_eq!(
        lines(&report(&mut core, seq, angle)),
        [
            "pitch.zero_deg = 5.5 (servo 1 stands there); save to keep it",
            "ok"
        ]
    );
    assert_eq!(core.settings().pitch.zero_deg, 5.5);
    assert_eq!(core.settings().yaw.zero_deg, 0.0);
    // Beyond the parameter's ±90°: refused, unchanged.
    let (seq, _) = job(&servo(&mut core, ServoSetup::Zero(1))).unwrap();
    let far = BusReport::Done(BusEnd::Angle {
        id: 1,
        tenths: 1200,
    });
    let reply = lines(&report(&mut core, seq, far));
    assert!(
        reply.len() == 1 && reply[0].starts_with("error:"),
        "{reply:?}"
    );
    assert_eq!(core.settings().pitch.zero_deg, 5.5);
}

#[test]
fn the_sdk_temperature_conversion() {
    // Half scale is the NTC's 25 °C; the simulator's 1854 is ≈ 30 °C
    // (the conversion rises as the raw value falls).
    assert!((celsius(2048) - 25.0).abs() < 0.01);
    assert!((celsius(1854) - 30.0).abs() < 0.5, "{}", celsius(1854));
    assert!(celsius(1000) > celsius(2000));
    assert!(celsius(0).is_finite() && celsius(u16::MAX).is_finite());
}
