//! State-machine property test of the core: random sequences of commands
//! (stop, goto, grid, patterns, target switches, set, save, …), servo
//! outcomes (arrivals, faults, recoveries, current and stale), stepper
//! events (arrivals, refusals, stops), galvo
//! events (done, refused, underruns, a gate closed under the core's feet)
//! and ticks with advancing time, fed through a model of the shell. After
//! every event the invariants hold:
//!
//! * the laser is dark while idle, and after any stop or fault until a
//!   deliberate drawing run (and, after a fault, an arrival) lights it;
//! * every command gets exactly one closing reply, other events none;
//! * every stop reaches every actuator: the gate closes and the galvo
//!   gets `Stop` after it (the stepper too, when it draws), and no servo move or galvo job is sent until
//!   a new run starts (the servo protocol has no stop request: the servos
//!   finish their move, dark);
//! * the status view agrees with the outputs and with itself.

extern crate std;

use std::vec;
use std::vec::Vec;

use embassy_time::{Duration, Instant};
use proptest::prelude::*;

use super::{Action, ActionSink, Core, Event, GalvoReadout, Inputs, Line, Readings};
use crate::command::{Command, PresetCommand};
use crate::domain::{Actuator, AimModel, Figure, GridPattern, Pattern, PointCm, Rotation};
use crate::galvo::{
    GALVO_REQUEST_DEPTH, GalvoError, GalvoEvent, GalvoRequest, ScanPhase, Underrun,
};
use crate::servo::task::{ServoFault, ServoOutcome, ServoRequest};
use crate::settings::{JumpPlanner, LaserMode, PARAMS};
use crate::status::Activity;
use crate::stepper::{StepperEvent, StepperRefusal, StepperRequest};

impl ActionSink for Vec<Action> {
    fn act(&mut self, action: Action) {
        self.push(action);
    }
}

/// One step of a random sequence.
#[derive(Debug, Clone)]
enum Step {
    Command(Command, SaveOk),
    StopButton,
    Arrived {
        current: bool,
        tenths: (i16, i16),
    },
    Fault {
        current: bool,
        id: u8,
    },
    Recovered {
        id: u8,
    },
    Superseded,
    GalvoDone {
        current: bool,
    },
    GalvoRefused {
        current: bool,
    },
    /// The galvo loop underruns: the first time it closes the gate itself,
    /// the next time it reports it (other events may come in between).
    GalvoUnderrun,
    GalvoConfigRefused,
    /// The galvo loop takes queued requests.
    GalvoTakes(usize),
    StepperArrived {
        current: bool,
        steps: (i16, i16),
    },
    StepperRefused {
        current: bool,
    },
    StepperStopped,
    /// A limit switch halted the steps (1–3), homing ended (4) or failed.
    StepperLimit(u8),
    Dwell,
    Tick {
        ms: u64,
    },
}

/// The store's answer if the command is `save`.
#[derive(Debug, Clone, Copy)]
struct SaveOk(bool);

fn point() -> impl Strategy<Value = PointCm> {
    (-40.0..40.0f64, -30.0..30.0f64).prop_map(|(x_cm, y_cm)| PointCm { x_cm, y_cm })
}

fn pattern() -> impl Strategy<Value = Pattern> {
    prop_oneof![
        3 => proptest::sample::select(GridPattern::ALL.to_vec()).prop_map(Pattern::Grid),
        1 => (point(), point()).prop_map(|(from, to)| Pattern::Path(Figure::Line { from, to })),
        1 => (point(), 0.0..15.0f64, any::<bool>()).prop_map(|(centre, radius_cm, cw)| {
            let rotation = if cw { Rotation::Cw } else { Rotation::Ccw };
            Pattern::Path(Figure::Circle { centre, radius_cm, rotation })
        }),
        1 => (point(), point()).prop_map(|(a, b)| Pattern::Path(Figure::Rect { a, b })),
        1 => (point(), 0.5..20.0f64).prop_map(|(centre, size_cm)| Pattern::Path(Figure::Tuning { centre, size_cm })),
    ]
}

fn command() -> impl Strategy<Value = Command> {
    let actuator = proptest::sample::select(vec![
        Actuator::Gimbal,
        Actuator::Galvo,
        Actuator::Both,
        Actuator::Stepper,
    ]);
    let mode = proptest::sample::select(vec![LaserMode::Auto, LaserMode::Dwell, LaserMode::Off]);
    let param = 0..PARAMS.len();
    prop_oneof![
        4 => (pattern(), any::<bool>()).prop_map(|(pattern, once)| Command::Pattern { pattern, once }),
        3 => point().prop_map(Command::Goto),
        2 => (-4i8..5, -4i8..5).prop_map(|(xi, yi)| Command::Grid { xi, yi }),
        3 => Just(Command::Stop),
        1 => Just(Command::Home),
        3 => actuator.prop_map(Command::Target),
        2 => mode.prop_map(Command::Laser),
        1 => any::<bool>().prop_map(|seed| Command::Model(if seed { AimModel::Seed } else { AimModel::Exact })),
        1 => any::<bool>().prop_map(|seed| Command::Planner(if seed { JumpPlanner::Seed } else { JumpPlanner::Optimal })),
        3 => (param.clone(), -0.1..1.1f64).prop_map(|(i, f)| {
            let param = &PARAMS[i];
            Command::Set { param, value: param.min + f * (param.max - param.min) }
        }),
        1 => param.prop_map(|i| Command::Get(&PARAMS[i])),
        1 => Just(Command::Save),
        1 => (0u8..4, any::<u8>()).prop_map(|(op, n)| Command::Preset(match op {
            0 => PresetCommand::Set(n),
            1 => PresetCommand::Clear(n),
            _ => PresetCommand::Goto(n),
        })),
        1 => Just(Command::Status),
        1 => Just(Command::GalvoStatus),
        1 => Just(Command::Params),
        1 => Just(Command::Help),
        1 => Just(Command::Version),
    ]
}

fn step() -> impl Strategy<Value = Step> {
    let current = proptest::bool::weighted(0.85);
    prop_oneof![
        6 => (command(), any::<bool>()).prop_map(|(c, ok)| Step::Command(c, SaveOk(ok))),
        1 => Just(Step::StopButton),
        8 => (current, (-900i16..900, -900i16..900))
            .prop_map(|(current, tenths)| Step::Arrived { current, tenths }),
        1 => (current, 0u8..3).prop_map(|(current, id)| Step::Fault { current, id }),
        1 => (0u8..3).prop_map(|id| Step::Recovered { id }),
        1 => Just(Step::Superseded),
        4 => current.prop_map(|current| Step::GalvoDone { current }),
        1 => current.prop_map(|current| Step::GalvoRefused { current }),
        1 => Just(Step::GalvoUnderrun),
        1 => Just(Step::GalvoConfigRefused),
        3 => (0..=GALVO_REQUEST_DEPTH).prop_map(Step::GalvoTakes),
        4 => (current, (-900i16..900, -900i16..900))
            .prop_map(|(current, steps)| Step::StepperArrived { current, steps }),
        1 => current.prop_map(|current| Step::StepperRefused { current }),
        1 => Just(Step::StepperStopped),
        1 => (0u8..6).prop_map(Step::StepperLimit),
        6 => Just(Step::Dwell),
        3 => (0u64..2_000).prop_map(|ms| Step::Tick { ms }),
    ]
}

/// The core and a model of the shell and of what it drives.
struct Harness {
    core: Core,
    now: Instant,
    /// Whether a galvo loop serves the link.
    attached: bool,
    /// Whether a stepper task serves its link.
    stepper_attached: bool,
    /// Free slots in the galvo request queue.
    galvo_room: usize,
    /// The master gate: open, and closed by the galvo loop since the core
    /// last closed it.
    gate_open: bool,
    gate_stolen: bool,
    /// The gimbal laser output.
    lit: bool,
    /// A run started since the last stop (anything may be sent).
    running: bool,
    /// A servo fault was reported and no arrival since.
    fault_since_arrival: bool,
    /// The last servo move, while its outcome is still owed.
    move_owed: Option<u32>,
    /// The last stepper move, while its report is still owed.
    step_owed: Option<u32>,
    /// The last galvo job, while its report is still owed.
    job_owed: Option<u32>,
    /// Underrun reports the galvo loop still owes.
    underruns_owed: u32,
}

impl Harness {
    fn new(attached: bool, stepper_attached: bool) -> Self {
        let mut harness = Self {
            core: Core::new(Instant::from_secs(1)),
            now: Instant::from_secs(1),
            attached,
            stepper_attached,
            galvo_room: GALVO_REQUEST_DEPTH,
            gate_open: false,
            gate_stolen: false,
            lit: false,
            running: false,
            fault_since_arrival: false,
            move_owed: None,
            step_owed: None,
            job_owed: None,
            underruns_owed: 0,
        };
        harness.dispatch(
            Event::SettingsLoaded(Err(crate::settings::RecordError::Missing)),
            true,
        );
        harness
    }

    fn readings(&self) -> Readings {
        Readings {
            galvo: GalvoReadout {
                phase: ScanPhase::Idle,
                queued: GALVO_REQUEST_DEPTH - self.galvo_room,
                underruns: 0,
                halves: 0,
                refill: None,
            },
            implausible_readings: 0,
        }
    }

    /// Runs `step`; `Err` names the broken invariant.
    fn step(&mut self, step: &Step) -> Result<(), std::string::String> {
        let galvo_step = matches!(
            step,
            Step::GalvoDone { .. }
                | Step::GalvoRefused { .. }
                | Step::GalvoUnderrun
                | Step::GalvoConfigRefused
                | Step::GalvoTakes(_)
        );
        if galvo_step && !self.attached {
            // No galvo loop: nothing reports.
            return Ok(());
        }
        let stepper_step = matches!(
            step,
            Step::StepperArrived { .. }
                | Step::StepperRefused { .. }
                | Step::StepperStopped
                | Step::StepperLimit(_)
        );
        if stepper_step && !self.stepper_attached {
            return Ok(());
        }
        let Some((event, save_ok)) = self.event(step) else {
            return Ok(());
        };
        let is_command = matches!(event, Event::Command { .. });
        let stops = matches!(
            event,
            Event::StopRequest
                | Event::Command {
                    command: Command::Stop,
                    ..
                }
        );
        // A stop reaches the stepper when it drew before the event.
        let stepper_drew = self.core.actuator.uses_stepper();
        let actions = self.dispatch(event, save_ok);
        self.check(&actions, is_command, stops, stepper_drew)
    }

    /// The event of `step` and the store's answer to a save (`None`: the
    /// step only changes the world around the core).
    fn event(&mut self, step: &Step) -> Option<(Event, bool)> {
        let event = match *step {
            Step::Command(command, SaveOk(ok)) => {
                let readings = self.readings();
                (Event::Command { command, readings }, ok)
            }
            Step::StopButton => (Event::StopRequest, true),
            Step::Arrived { current, tenths } => {
                self.fault_since_arrival = false;
                let seq = Self::seq(current, &mut self.move_owed);
                let (yaw_tenths, pitch_tenths) = tenths;
                let arrived = ServoOutcome::Arrived {
                    seq,
                    yaw_tenths,
                    pitch_tenths,
                };
                (Event::Servo(arrived), true)
            }
            Step::Fault { current, id } => {
                // Servo faults do not concern the stepper.
                self.fault_since_arrival |= self.core.actuator.uses_gimbal();
                let seq = Self::seq(current, &mut self.move_owed);
                let fault = ServoFault::NoResponse;
                (Event::Servo(ServoOutcome::Fault { seq, id, fault }), true)
            }
            Step::Recovered { id } => (Event::Servo(ServoOutcome::Recovered { id }), true),
            Step::Superseded => {
                let seq = Self::seq(false, &mut self.move_owed);
                (Event::Servo(ServoOutcome::Superseded { seq }), true)
            }
            Step::StepperArrived { .. }
            | Step::StepperRefused { .. }
            | Step::StepperStopped
            | Step::StepperLimit(_) => (Event::Stepper(self.stepper_event(step)), true),
            Step::GalvoDone { current } => {
                let seq = Self::seq(current, &mut self.job_owed);
                (Event::Galvo(GalvoEvent::Done { seq }), true)
            }
            Step::GalvoRefused { current } => {
                let seq = Self::seq(current, &mut self.job_owed);
                let error = GalvoError::OutOfRange;
                (Event::Galvo(GalvoEvent::Refused { seq, error }), true)
            }
            Step::GalvoUnderrun if self.underruns_owed == 0 => {
                // The loop closes the gate at once; its report comes later.
                self.gate_open = false;
                self.gate_stolen = true;
                self.underruns_owed += 1;
                self.galvo_room = GALVO_REQUEST_DEPTH;
                // Dark at once through the gate; the core learns it with
                // the next event.
                return None;
            }
            Step::GalvoUnderrun => {
                self.underruns_owed -= 1;
                let underrun = GalvoEvent::Underrun(Underrun { halves: 1 });
                (Event::Galvo(underrun), true)
            }
            Step::GalvoConfigRefused => {
                let refused = GalvoEvent::ConfigRefused(GalvoError::Planner);
                (Event::Galvo(refused), true)
            }
            Step::GalvoTakes(n) => {
                self.galvo_room = (self.galvo_room + n).min(GALVO_REQUEST_DEPTH);
                return None;
            }
            Step::Dwell => match self.core.dwell_deadline() {
                Some(at) => {
                    self.now = self.now.max(at);
                    (Event::DwellEnded, true)
                }
                None => (Event::Tick, true),
            },
            Step::Tick { ms } => {
                self.now += Duration::from_millis(ms);
                (Event::Tick, true)
            }
        };
        Some(event)
    }

    /// The stepper's report of a `Step::Stepper*` step.
    fn stepper_event(&mut self, step: &Step) -> StepperEvent {
        match *step {
            Step::StepperArrived { current, steps } => {
                let seq = Self::seq(current, &mut self.step_owed);
                let steps = [i32::from(steps.0), i32::from(steps.1)];
                StepperEvent::Arrived { seq, steps }
            }
            Step::StepperRefused { current } => {
                let seq = Self::seq(current, &mut self.step_owed);
                let why = StepperRefusal::SoftLimit;
                StepperEvent::Refused { seq, why }
            }
            Step::StepperStopped => {
                self.step_owed = None;
                StepperEvent::Stopped { steps: [0; 2] }
            }
            Step::StepperLimit(kind) => {
                self.step_owed = None;
                let steps = [0; 2];
                match kind {
                    1..=3 => StepperEvent::LimitHit { axes: kind, steps },
                    4 => StepperEvent::Homed { steps },
                    _ => StepperEvent::HomingFailed {
                        why: crate::stepper::HomingFailure::Interrupted,
                        steps,
                    },
                }
            }
            _ => unreachable!("not a stepper step: {step:?}"),
        }
    }

    /// The request number an outcome reports: the request still owed one
    /// (`current`; it is then answered), or a stale one.
    fn seq(current: bool, owed: &mut Option<u32>) -> u32 {
        match (current, *owed) {
            (true, Some(seq)) => {
                *owed = None;
                seq
            }
            (_, Some(seq)) => seq.wrapping_sub(1),
            (_, None) => u32::MAX,
        }
    }

    /// Hands `event` to the core as the shell does, follow-ups included
    /// (a save answered `save_ok`); returns every action.
    fn dispatch(&mut self, event: Event, save_ok: bool) -> Vec<Action> {
        let mut all = Vec::new();
        let mut next = Some(event);
        let mut refused = false;
        self.running = self.core.run.is_some();
        for round in 0.. {
            let Some(event) = next.take() else { break };
            // A pattern check takes at most a few dozen steps.
            assert!(round < 1_000, "the follow-ups of an event never end");
            let mut actions = Vec::new();
            let inputs = Inputs {
                now: self.now,
                galvo_room: self.attached.then_some(self.galvo_room),
                galvo_bisection: self.attached,
                stepper_attached: self.stepper_attached,
            };
            self.core.on(inputs, event, &mut actions);
            let mut follow = None;
            for action in &actions {
                self.apply(action, &mut follow, &mut refused);
            }
            all.extend(actions);
            next = match follow {
                Some(Action::Yield) => Some(Event::CheckStep),
                // A saved preset when the store works, none otherwise.
                Some(Action::LoadPreset(n)) => Some(Event::PresetLoaded {
                    n,
                    point: save_ok.then_some(PointCm::new(1.0, -2.0)),
                }),
                Some(_) => Some(Event::Saved(if save_ok {
                    Ok(())
                } else {
                    Err("flash write failed")
                })),
                None => {
                    // The shell opens the gate again for a lit laser (after
                    // `laser off` shut it); refused when the loop closed it.
                    let lost = core::mem::take(&mut refused) || (self.lit && self.gate_stolen);
                    self.gate_open |= self.lit && !self.gate_stolen;
                    lost.then_some(Event::GateLost)
                }
            };
        }
        all
    }

    /// What the shell does with `action` (and what the invariants on
    /// single actions are).
    fn apply(&mut self, action: &Action, follow: &mut Option<Action>, refused: &mut bool) {
        match action {
            Action::Servo(ServoRequest::Move { seq, .. }) => {
                assert!(self.running, "servo move while stopped");
                assert!(self.core.actuator.uses_gimbal(), "servo move on the galvo");
                self.move_owed = Some(*seq);
            }
            Action::Servo(ServoRequest::Setup { .. }) => {
                assert!(!self.running, "servo set-up while running");
            }
            Action::Galvo(GalvoRequest::Stop) => {
                // The loop drops its jobs unreported.
                self.galvo_room = GALVO_REQUEST_DEPTH - 1;
                self.job_owed = None;
            }
            Action::Galvo(request) => {
                assert!(self.running, "galvo job while stopped");
                assert!(self.core.actuator.uses_galvo(), "galvo job on the gimbal");
                assert!(self.galvo_room > 0, "galvo job into a full queue");
                self.galvo_room -= 1;
                match *request {
                    GalvoRequest::Point {
                        seq, x_mm, y_mm, ..
                    } => {
                        assert!(x_mm.is_finite() && y_mm.is_finite());
                        self.job_owed = Some(seq);
                    }
                    GalvoRequest::Path { seq, .. } => self.job_owed = Some(seq),
                    GalvoRequest::Stop => {}
                }
            }
            Action::CloseGate => {
                self.gate_open = false;
                self.gate_stolen = false;
            }
            Action::ShutGate => self.gate_open = false,
            Action::GimbalLaser(on) => {
                let lit = *on && !self.gate_stolen;
                *refused |= *on && !lit;
                self.gate_open |= lit;
                self.lit = lit;
            }
            Action::Note(super::super::laser::LaserEvent::Stopped { .. }) => self.running = false,
            Action::Note(super::super::laser::LaserEvent::RunStarted) => self.running = true,
            Action::Save | Action::Yield | Action::SavePreset { .. } | Action::LoadPreset(_) => {
                *follow = Some(action.clone())
            }
            Action::Stepper(StepperRequest::MoveTo { seq, point, .. }) => {
                assert!(self.running, "stepper move while stopped");
                assert!(self.stepper_attached, "stepper move without a stepper");
                assert!(
                    self.core.actuator.uses_stepper(),
                    "stepper move off the stepper"
                );
                assert!(point.x_cm.is_finite() && point.y_cm.is_finite());
                self.step_owed = Some(*seq);
            }
            Action::Stepper(_) => self.step_owed = None,
            Action::ConfigureGalvo(_)
            | Action::ArmLaser { .. }
            | Action::ConfigureStepper(_)
            | Action::AllowGalvoLaser(_)
            | Action::GimbalPower(_)
            | Action::Note(_)
            | Action::Line(_) => {}
        }
    }

    /// The invariants after one event and its follow-ups.
    fn check(
        &self,
        actions: &[Action],
        is_command: bool,
        stops: bool,
        stepper_drew: bool,
    ) -> Result<(), std::string::String> {
        let closers = actions
            .iter()
            .filter(|a| matches!(a, Action::Line(Line::Ok | Line::Error(_))))
            .count();
        let expected = usize::from(is_command);
        if closers != expected {
            return Err(std::format!(
                "{closers} closing replies, {expected} expected"
            ));
        }
        // Every stop reaches every actuator.
        for (i, _) in actions.iter().enumerate().filter(|(_, a)| {
            matches!(
                a,
                Action::Note(super::super::laser::LaserEvent::Stopped { .. })
            )
        }) {
            let rest = &actions[i..];
            let closes = rest.contains(&Action::CloseGate);
            let galvo = rest.iter().any(|a| *a == Action::Galvo(GalvoRequest::Stop));
            if !(closes && galvo) {
                return Err("a stop that does not close the gate and stop the galvo".into());
            }
            let stepper = rest
                .iter()
                .any(|a| *a == Action::Stepper(StepperRequest::Stop));
            if stepper_drew && !stepper {
                return Err("a stop that does not stop the stepper".into());
            }
        }
        if stops && (self.core.run.is_some() || self.lit || self.running) {
            return Err("stop left something running or lit".into());
        }
        if self.core.pending.is_some() {
            return Err("a command still pending after its follow-ups".into());
        }
        self.check_outputs()
    }

    /// The invariants on the outputs and the status view.
    fn check_outputs(&self) -> Result<(), std::string::String> {
        let view = self.core.status();
        // Homing has no point either (and is dark).
        let idle = matches!(view.activity, Activity::Idle | Activity::Homing);
        if idle != view.phase.is_none() || idle != view.point_index.is_none() {
            return Err("status view contradicts itself".into());
        }
        if view.laser_on != self.lit {
            return Err("status view disagrees with the laser output".into());
        }
        if self.lit {
            let mode = self.core.settings.laser_mode;
            let why = if idle {
                Some("laser on while idle")
            } else if !self.running {
                Some("laser on after a stop")
            } else if self.fault_since_arrival && self.core.actuator.uses_gimbal() {
                Some("laser on after a fault, before an arrival")
            } else if self.core.actuator == Actuator::Galvo {
                Some("gimbal laser on while only the galvo draws")
            } else if mode == LaserMode::Off {
                Some("laser on in laser off")
            } else if !self.gate_open || self.gate_stolen {
                Some("laser on through a closed gate")
            } else {
                None
            };
            if let Some(why) = why {
                return Err(why.into());
            }
        }
        if self.core.dwell_deadline().is_some()
            && view.phase != Some(crate::status::Phase::Dwelling)
        {
            return Err("dwell deadline armed outside a dwell".into());
        }
        Ok(())
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn random_event_sequences_keep_the_invariants(
        attached in any::<bool>(),
        stepper_attached in any::<bool>(),
        steps in proptest::collection::vec(step(), 1..160),
    ) {
        let mut harness = Harness::new(attached, stepper_attached);
        for (i, step) in steps.iter().enumerate() {
            if let Err(why) = harness.step(step) {
                prop_assert!(false, "step {i} {step:?}: {why}");
            }
        }
    }
}
