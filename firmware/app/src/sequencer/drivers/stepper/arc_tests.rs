//! G-code arcs on the stepper (issue 25): one move per block.

extern crate std;

use std::vec::Vec;

use embassy_time::Instant;

use crate::command::{Command, GrblLine};
use crate::domain::Actuator;
use crate::sequencer::gcode::tests::{READINGS, closers};
use crate::sequencer::machine::{Action, Core, Event, Inputs};
use crate::stepper::{MoveShape, StepperEvent, StepperRequest};

fn on(core: &mut Core, ms: u64, event: Event) -> Vec<Action> {
    let inputs = Inputs {
        now: Instant::from_millis(ms),
        galvo_room: Some(8),
        galvo_bisection: false,
        stepper_attached: true,
    };
    let mut out = Vec::new();
    core.on(inputs, event, &mut out);
    out
}

fn command(core: &mut Core, ms: u64, command: Command) -> Vec<Action> {
    on(
        core,
        ms,
        Event::Command {
            command,
            readings: READINGS,
        },
    )
}

fn line(core: &mut Core, ms: u64, text: &str) -> Vec<Action> {
    command(
        core,
        ms,
        Command::Grbl(GrblLine::new(text).expect("short line")),
    )
}

/// The stepper moves requested: (seq, shape).
fn moves(actions: &[Action]) -> Vec<(u32, MoveShape)> {
    actions
        .iter()
        .filter_map(|a| match a {
            Action::Stepper(StepperRequest::MoveTo { seq, shape, .. }) => Some((*seq, *shape)),
            _ => None,
        })
        .collect()
}

/// Reports move `seq` taken and then at rest; what came out.
fn take_and_arrive(core: &mut Core, ms: u64, seq: u32) -> Vec<Action> {
    let mut out = on(core, ms, Event::Stepper(StepperEvent::Taken { seq }));
    out.extend(on(
        core,
        ms + 1,
        Event::Stepper(StepperEvent::Arrived { seq, steps: [0, 0] }),
    ));
    out
}

/// `G2`/`G3` on the stepper is one move: at its arrival the block is done
/// (before the fix the block was split into the arc's `$12` chords on
/// the stepper too, and each further "chord" handed the whole arc over
/// again from its end: a full circle, lit, dozens of times).
#[test]
fn an_arc_is_one_stepper_move_and_ends_at_its_arrival() {
    let mut core = Core::new(Instant::from_millis(0));
    assert_eq!(
        closers(&command(&mut core, 0, Command::Target(Actuator::Stepper))),
        1
    );
    line(&mut core, 1, "$X");
    let rapid = moves(&line(&mut core, 2, "G0 X10 Y0"));
    assert_eq!(rapid.len(), 1, "{rapid:?}");
    assert!(moves(&take_and_arrive(&mut core, 3, rapid[0].0)).is_empty());
    line(&mut core, 5, "M3 S1000");
    for (k, arc) in [
        "G2 X0 Y-10 I-10 J0 F600",
        "G3 X10 Y0 I0 J10",
        "G2 X10 Y0 I-10 J0",
        "G3 X-10 Y0 R10",
    ]
    .into_iter()
    .enumerate()
    {
        let ms = 10 + 10 * k as u64;
        let sent = moves(&line(&mut core, ms, arc));
        let [(seq, MoveShape::Arc { .. })] = sent[..] else {
            panic!("{arc}: {sent:?}");
        };
        let again = moves(&take_and_arrive(&mut core, ms + 1, seq));
        assert!(again.is_empty(), "{arc}: handed over again: {again:?}");
    }
    assert!(core.gcode.motion.current.is_none(), "every block done");
}
