//! `arm`, the controls' `status` line, `?`'s `Door` state and the stop
//! cause, on the pure core with the controls' state noted as the shell
//! notes it.

extern crate std;

use std::string::String;
use std::vec::Vec;

use embassy_time::Instant;

use super::super::machine::{Action, Core, Event, Inputs, Line};
use super::NO_CONTROLS;
use crate::command::{Command, RealtimeRequest};
use crate::grbl::realtime::Realtime;
use crate::laser_controls::{ControlInputs, ControlsState, ControlsView, LatchCause};
use crate::sequencer::LaserEvent;
use crate::settings::PARAMS;

fn on(core: &mut Core, controls: Option<ControlsView>, event: Event) -> Vec<Action> {
    let inputs = Inputs {
        now: Instant::from_millis(100),
        galvo_room: None,
        galvo_bisection: false,
        stepper_attached: false,
    };
    core.note_laser_controls(controls);
    let mut out = Vec::new();
    core.on(inputs, event, &mut out);
    out
}

fn command(core: &mut Core, controls: Option<ControlsView>, command: Command) -> Vec<Action> {
    let readings = crate::sequencer::gcode::tests::READINGS;
    on(core, controls, Event::Command { command, readings })
}

fn texts(out: &[Action]) -> Vec<String> {
    out.iter()
        .filter_map(|a| match a {
            Action::Line(Line::Data(t) | Line::Push(t) | Line::Error(t)) => {
                Some(String::from(t.as_str()))
            }
            _ => None,
        })
        .collect()
}

fn view(interlock_closed: bool, state: ControlsState) -> Option<ControlsView> {
    Some(ControlsView {
        inputs: ControlInputs {
            interlock_closed,
            key_on: true,
        },
        state,
    })
}

const POWER_UP: ControlsState = ControlsState::Latched(LatchCause::PowerUp);

#[test]
fn arm_asks_the_controls_with_the_saved_delay_or_says_why_not() {
    let mut core = Core::new(Instant::from_millis(0));
    let out = command(&mut core, None, Command::Arm);
    assert_eq!(texts(&out), [NO_CONTROLS]);
    let out = command(&mut core, view(false, POWER_UP), Command::Arm);
    assert_eq!(texts(&out), ["interlock open: close it, then arm"]);
    assert!(!out.iter().any(|a| matches!(a, Action::ArmLaser { .. })));
    let out = command(&mut core, view(true, POWER_UP), Command::Arm);
    assert_eq!(
        out,
        [Action::ArmLaser { delay_ms: 3000 }, Action::Line(Line::Ok)]
    );
    let param = PARAMS
        .iter()
        .find(|p| p.name == "laser.emission_delay_s")
        .unwrap();
    command(&mut core, None, Command::Set { param, value: 5.5 });
    let out = command(&mut core, view(true, POWER_UP), Command::Arm);
    assert_eq!(out[0], Action::ArmLaser { delay_ms: 5500 });
}

#[test]
fn status_and_the_grbl_report_show_the_controls() {
    let mut core = Core::new(Instant::from_millis(0));
    let lines = texts(&command(&mut core, None, Command::Status));
    assert!(lines.contains(&"laser controls: none on this board".into()));
    let lines = texts(&command(&mut core, view(false, POWER_UP), Command::Status));
    assert!(
        lines.contains(&"laser controls: interlock open, key on, not armed since power-up".into()),
        "{lines:?}"
    );
    let report = |core: &mut Core, controls| {
        let request = RealtimeRequest {
            command: Realtime::StatusReport,
            rx_free_bytes: 100,
        };
        texts(&on(core, controls, Event::Realtime(request)))
            .pop()
            .unwrap()
    };
    assert!(report(&mut core, None).starts_with("<Idle|"));
    assert!(report(&mut core, view(false, POWER_UP)).starts_with("<Door:1|"));
    assert!(report(&mut core, view(true, POWER_UP)).starts_with("<Door:0|"));
    assert!(report(&mut core, view(true, ControlsState::Arming)).starts_with("<Door:3|"));
    assert!(report(&mut core, view(true, ControlsState::Armed)).starts_with("<Idle|"));
}

#[test]
fn a_stop_request_after_a_latch_names_the_cause() {
    let mut core = Core::new(Instant::from_millis(0));
    let stopped = |out: &[Action]| {
        out.iter().find_map(|a| match a {
            Action::Note(LaserEvent::Stopped { why }) => Some(*why),
            _ => None,
        })
    };
    let opened = view(false, ControlsState::Latched(LatchCause::InterlockOpened));
    assert_eq!(
        stopped(&on(&mut core, opened, Event::StopRequest)),
        Some("interlock opened")
    );
    assert_eq!(
        stopped(&on(&mut core, None, Event::StopRequest)),
        Some("stop button")
    );
}
