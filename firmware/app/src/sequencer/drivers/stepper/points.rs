//! The core's side of the stepper pan/tilt (`target stepper`): each point
//! of a run to the stepper task (grid and goto points straight in joint
//! space, paths as their exact lines and arcs — or, with `model seed`, the
//! seed's point-by-point interpolation joined by board lines), its
//! arrivals back into the dwell, its refusals into an error and a stop,
//! a stop into a deceleration at the limit (the laser dark at once:
//! [`Session::stop`](crate::sequencer::gcode::context::Session::stop) closes the gate first). The stop button halts the steps
//! at once through the link itself.

use crate::domain::{Aim, Pattern, PointCm, Segment, Target, Unit};
use crate::log;
use crate::sequencer::drivers::stage::Stage;
use crate::sequencer::drivers::stepper::config;
use crate::sequencer::drivers::stepper::gcode::junction;
use crate::sequencer::drivers::{Driver, Drivers, Said};
use crate::sequencer::io::{Action, ActionSink};
use crate::sequencer::run::{Run, RunKind};
use crate::settings::Settings;
use crate::stepper::{HomingFailure, MoveShape, StepperEvent, StepperRequest};
use crate::text::{Fixed, reply_text};
use kinematics_core::frames::BoardPoint;

/// Sends the stepper task the parameters of `settings` (applied at rest;
/// the junction deviation the product's, `stepper.junction_deg`:
/// `junction_deg`, what it was told last, is reset).
pub(in crate::sequencer) fn configure(
    settings: &Settings,
    junction_deg: &mut Option<f64>,
    out: &mut dyn ActionSink,
) {
    *junction_deg = None;
    out.act(Action::ConfigureStepper(config(settings)));
}

/// Decelerates the stepper to rest (when it draws: `drivers`).
pub(in crate::sequencer) fn stop(drivers: Drivers, out: &mut dyn ActionSink) {
    if drivers.hands_over_blocks() {
        out.act(Action::Stepper(StepperRequest::Stop));
    }
}

/// Sends the current point `target` of the run to the stepper task:
/// travel (`approach`, grid and goto points) straight in joint space, a
/// path's next point along the board line; `false` when no run.
pub(in crate::sequencer) fn aim(
    st: &mut Stage,
    target: Target,
    approach: bool,
    out: &mut dyn ActionSink,
) -> bool {
    let Some(run) = *st.run else { return false };
    let shape = match (run.kind, approach) {
        (RunKind::Traced { pattern, .. }, false) => traced_shape(&pattern, run.index),
        // The seed's point-by-point method: straight board lines between
        // the interpolated points.
        (RunKind::Path { .. }, false) => MoveShape::Line,
        _ => MoveShape::Travel,
    };
    junction(st.settings, &mut st.gcode.stepper_junction_deg, false, out);
    let seq = st.take_seq();
    let point = BoardPoint::new(target.point.x_cm, target.point.y_cm);
    out.act(Action::Stepper(StepperRequest::MoveTo {
        seq,
        point,
        shape,
        feed_mm_s: None,
    }));
    out.act(Action::Note(
        crate::sequencer::laser::LaserEvent::GimbalMoveSent,
    ));
    log::info!(
        "stepper target ({}, {}) cm ({})",
        target.point.x_cm,
        target.point.y_cm,
        shape.name()
    );
    if let Some(run) = st.run.as_mut() {
        run.seq = seq;
    }
    // What `status` and the recorders show: the target and its joint
    // angles on the stepper (no servo: wire 0).
    let joints = config(st.settings).gimbal.ik(point).unwrap_or_default();
    let aim = Aim {
        yaw_deg: joints.yaw_deg,
        pitch_deg: joints.pitch_deg,
        yaw_wire: 0,
        pitch_wire: 0,
    };
    *st.last_aim = Some((target, aim));
    true
}

/// How a traced run of `pattern` runs (`None`: a figure of more than
/// one stroke, which the stepper does not trace).
pub(in crate::sequencer) fn traced(pattern: Pattern, once: bool) -> Option<RunKind> {
    let Pattern::Path(figure) = pattern else {
        return None;
    };
    let single = figure.stroke(1, Unit::BoardCm).is_none();
    (single && figure.stroke(0, Unit::BoardCm).is_some())
        .then_some(RunKind::Traced { pattern, once })
}

/// Point `index` of a traced pass: the stroke's start, then each
/// segment's end (`None` past the last).
pub(in crate::sequencer) fn traced_target(pattern: &Pattern, index: usize) -> Option<Target> {
    let Pattern::Path(figure) = pattern else {
        return None;
    };
    let stroke = figure.stroke(0, Unit::BoardCm)?;
    let [x, y] = match index.checked_sub(1) {
        None => stroke.start,
        Some(k) => match *stroke.segments.get(k)? {
            Segment::Line { to } => to,
            Segment::Arc { end, .. } => end,
        },
    };
    Some(Target {
        point: PointCm::new(x, y),
        grid: None,
    })
}

/// How the stepper gets to point `index` of a traced pass.
fn traced_shape(pattern: &Pattern, index: usize) -> MoveShape {
    let Pattern::Path(figure) = pattern else {
        return MoveShape::Travel;
    };
    let segment = index
        .checked_sub(1)
        .and_then(|k| figure.stroke(0, Unit::BoardCm)?.segments.get(k).copied());
    match segment {
        Some(Segment::Line { .. }) => MoveShape::Line,
        Some(Segment::Arc {
            centre: [x, y],
            rotation,
            ..
        }) => MoveShape::Arc {
            centre: BoardPoint::new(x, y),
            rotation,
        },
        None => MoveShape::Travel,
    }
}

/// What a report of the stepper task the G-code session did not take
/// asks of the core (`run`: the active run; `target`: the board point,
/// cm, of its current point, for messages).
pub(in crate::sequencer) fn said(
    event: StepperEvent,
    settings: &Settings,
    run: Option<Run>,
    target: (f64, f64),
) -> Said {
    match event {
        StepperEvent::Arrived { seq, steps } => {
            log::info!("stepper arrived at {} {} steps", steps[0], steps[1]);
            Said::Arrived(seq)
        }
        StepperEvent::Refused { seq, why } => {
            if run.is_none_or(|r| r.seq != seq) {
                return Said::Nothing;
            }
            let name = run.map_or("goto", |r| r.kind.name());
            let notice = reply_text(format_args!(
                "error: {name} stopped, laser off: point ({}, {}) cm refused by the stepper: {why:?}",
                Fixed::<2>(target.0),
                Fixed::<2>(target.1),
            ));
            Said::Stop(Some(notice), "stepper refused the point")
        }
        StepperEvent::Taken { .. } => Said::Nothing,
        StepperEvent::Stopped { steps } => {
            log::info!("stepper at rest at {} {} steps", steps[0], steps[1]);
            Said::Nothing
        }
        StepperEvent::LimitHit { axes, steps } => {
            log::warning!("stepper limit switch at {} {} steps", steps[0], steps[1]);
            let which = ["", "pan", "tilt", "pan and tilt"][usize::from(axes & 3)];
            let notice = reply_text(format_args!(
                "error: stepper limit switch {which} hit: steps halted, laser off"
            ));
            Said::Stop(Some(notice), "limit switch")
        }
        StepperEvent::Homed { steps } => {
            let j = config(settings).joints_of(steps).unwrap_or_default();
            let notice = reply_text(format_args!(
                "homed: stepper at pan {} tilt {} deg",
                Fixed::<3>(j.yaw_deg),
                Fixed::<3>(j.pitch_deg)
            ));
            Said::Homed(notice, steps, None)
        }
        StepperEvent::HomingFailed { why, steps } => {
            let text = match why {
                HomingFailure::NoSwitches => "no homing switches configured",
                HomingFailure::NotFound(0) => "pan switch not found within the travel",
                HomingFailure::NotFound(_) => "tilt switch not found within the travel",
                HomingFailure::StillPressed(_) => "switch still closed after backing off",
                HomingFailure::Interrupted => "stopped",
                HomingFailure::BadConfig => "parameters refused for the homing moves",
            };
            let notice = reply_text(format_args!("error: home failed: {text}; not homed"));
            Said::Homed(notice, steps, Some(why))
        }
    }
}

/// Whether `home` / `$H` can home with `drivers` and `settings`: `Err`
/// with the reason when not the stepper, or no switches (nothing
/// changes; the power-up position stays step 0).
pub(in crate::sequencer) fn can_home(
    drivers: Drivers,
    settings: &Settings,
) -> Result<(), &'static str> {
    if !drivers.any(Driver::homes_with_switches) {
        return Err("home: only with target stepper");
    }
    let s = &settings.stepper;
    if s.pan.home_dir == 0.0 && s.tilt.home_dir == 0.0 {
        return Err(
            "home: no homing switches configured (stepper.pan.home_dir and stepper.tilt.home_dir are 0); the position stays as at power-up",
        );
    }
    Ok(())
}
