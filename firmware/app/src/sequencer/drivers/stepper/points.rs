//! The core's side of the stepper pan/tilt (`target stepper`): each point
//! of a run to the stepper task (grid and goto points straight in joint
//! space, paths as their exact lines and arcs — or, with `model seed`, the
//! seed's point-by-point interpolation joined by board lines), its
//! arrivals back into the dwell, its refusals into an error and a stop,
//! a stop into a deceleration at the limit (the laser dark at once:
//! [`Core::stop`] closes the gate first). The stop button halts the steps
//! at once through the link itself.

use crate::domain::{Aim, Pattern, PointCm, Segment, Target, Unit};
use crate::log;
use crate::sequencer::drivers::Driver;
use crate::sequencer::drivers::stepper::gcode::{config, junction};
use crate::sequencer::machine::{Action, ActionSink, Core};
use crate::sequencer::run::RunKind;
use crate::stepper::{HomingFailure, MoveShape, StepperConfig, StepperEvent, StepperRequest};
use crate::text::Fixed;
use kinematics_core::frames::BoardPoint;

impl Core {
    /// The stepper parameters from the settings ([`config`]).
    pub(in crate::sequencer) fn stepper_config(&self) -> StepperConfig {
        config(&self.settings)
    }

    /// Sends the stepper task its parameters (applied at rest; the
    /// junction deviation the product's, `stepper.junction_deg`).
    pub(in crate::sequencer) fn configure_stepper(&mut self, out: &mut dyn ActionSink) {
        self.gcode.stepper_junction_deg = None;
        out.act(Action::ConfigureStepper(self.stepper_config()));
    }

    /// The stepper plans with the junction deviation of `gcode` or of the
    /// product ([`junction`]).
    pub(in crate::sequencer) fn stepper_junction(&mut self, gcode: bool, out: &mut dyn ActionSink) {
        junction(
            &self.settings,
            &mut self.gcode.stepper_junction_deg,
            gcode,
            out,
        );
    }

    /// Decelerates the stepper to rest (when it draws).
    pub(in crate::sequencer) fn stop_stepper(&self, out: &mut dyn ActionSink) {
        if self.drivers().hands_over_blocks() {
            out.act(Action::Stepper(StepperRequest::Stop));
        }
    }

    /// Sends the current point to the stepper task: travel (`approach`,
    /// grid and goto points) straight in joint space, a path's next point
    /// along the board line.
    pub(in crate::sequencer) fn begin_stepper_move(
        &mut self,
        target: Target,
        approach: bool,
        out: &mut dyn ActionSink,
    ) -> bool {
        let Some(run) = self.run else { return false };
        let shape = match (run.kind, approach) {
            (RunKind::Traced { pattern, .. }, false) => Self::traced_shape(&pattern, run.index),
            // The seed's point-by-point method: straight board lines between
            // the interpolated points.
            (RunKind::Path { .. }, false) => MoveShape::Line,
            _ => MoveShape::Travel,
        };
        self.stepper_junction(false, out);
        self.next_seq = self.next_seq.wrapping_add(1);
        let seq = self.next_seq;
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
        if let Some(run) = self.run.as_mut() {
            run.seq = seq;
        }
        // What `status` and the recorders show: the target and its joint
        // angles on the stepper (no servo: wire 0).
        let joints = self.stepper_config().gimbal.ik(point).unwrap_or_default();
        let aim = Aim {
            yaw_deg: joints.yaw_deg,
            pitch_deg: joints.pitch_deg,
            yaw_wire: 0,
            pitch_wire: 0,
        };
        self.last_aim = Some((target, aim));
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

    /// The stepper task's report.
    pub(in crate::sequencer) fn stepper_event(
        &mut self,
        event: StepperEvent,
        out: &mut dyn ActionSink,
    ) {
        if let StepperEvent::Homed { .. } | StepperEvent::HomingFailed { .. } = event {
            self.stepper_homing = false;
        }
        if self.gcode_stepper_event(&event, out) {
            return;
        }
        match event {
            StepperEvent::Arrived { seq, steps } => {
                log::info!("stepper arrived at {} {} steps", steps[0], steps[1]);
                self.start_dwell(seq, out);
            }
            StepperEvent::Refused { seq, why } => {
                if self.run.is_none_or(|r| r.seq != seq) {
                    return;
                }
                let name = self.run.map_or("goto", |r| r.kind.name());
                let target = self.last_stepper_target();
                self.notify(
                    out,
                    format_args!(
                        "error: {name} stopped, laser off: point ({}, {}) cm refused by the stepper: {why:?}",
                        Fixed::<2>(target.0),
                        Fixed::<2>(target.1),
                    ),
                );
                self.stop("stepper refused the point", out);
            }
            StepperEvent::Taken { .. } => {}
            StepperEvent::Stopped { steps } => {
                log::info!("stepper at rest at {} {} steps", steps[0], steps[1]);
            }
            StepperEvent::LimitHit { axes, steps } => {
                log::warning!("stepper limit switch at {} {} steps", steps[0], steps[1]);
                let which = ["", "pan", "tilt", "pan and tilt"][usize::from(axes & 3)];
                self.notify(
                    out,
                    format_args!(
                        "error: stepper limit switch {which} hit: steps halted, laser off"
                    ),
                );
                self.stop("limit switch", out);
            }
            StepperEvent::Homed { steps } => {
                let j = self.stepper_config().joints_of(steps).unwrap_or_default();
                self.notify(
                    out,
                    format_args!(
                        "homed: stepper at pan {} tilt {} deg",
                        Fixed::<3>(j.yaw_deg),
                        Fixed::<3>(j.pitch_deg)
                    ),
                );
                self.gcode_homing_done(steps, None, out);
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
                self.notify(out, format_args!("error: home failed: {text}; not homed"));
                self.gcode_homing_done(steps, Some(why), out);
            }
        }
    }

    /// `home` / `$H` on the stepper: any run stops (laser dark), then the
    /// stepper task homes the axes with switches; `homed: …` or
    /// `error: home failed: …` follows.
    ///
    /// Errors: not the stepper, or no switches (nothing changes; the
    /// power-up position stays step 0).
    pub(in crate::sequencer) fn start_homing(
        &mut self,
        out: &mut dyn ActionSink,
    ) -> Result<(), &'static str> {
        if !self.drivers().any(Driver::homes_with_switches) {
            return Err("home: only with target stepper");
        }
        let s = &self.settings.stepper;
        if s.pan.home_dir == 0.0 && s.tilt.home_dir == 0.0 {
            return Err(
                "home: no homing switches configured (stepper.pan.home_dir and stepper.tilt.home_dir are 0); the position stays as at power-up",
            );
        }
        self.stop("home", out);
        out.act(Action::Stepper(StepperRequest::Home));
        self.stepper_homing = true;
        Ok(())
    }

    /// The board point (cm) of the run's current point, for messages.
    fn last_stepper_target(&self) -> (f64, f64) {
        self.status()
            .target
            .map_or((0.0, 0.0), |(t, _)| (t.point.x_cm, t.point.y_cm))
    }
}
