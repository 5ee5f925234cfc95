//! One G-code line from the console to a planned block on each actuator
//! (issue 21): `gcode.line.<actuator>`, the dearest of [`LINES`] seeded
//! random lines (G0, G1, G2/G3 with random coordinates and feeds), each
//! sent after a queue of [`BASE`] blocks so the look-ahead replans.
//!
//! Each line's figure is the sum of the windows the line goes through:
//!
//! * all actuators: the sequencer core taking the line as the console
//!   hands it over (`Core::on` with the grbl line: grbl parser, G-code
//!   session, motion queue, the driver's hand-over);
//! * gimbal: the next streaming tick of the core (`DwellEnded`), which
//!   replans the running block's exit speed through the look-ahead over
//!   the queue with the new line in it (and sends that tick's servo aim);
//! * galvo: the loop's path planner (`PathPlanner::line_to` / `arc_to` /
//!   `move_to`, a G0's jump slot) adding the line to a stroke that holds
//!   three segments, replanning them;
//! * stepper: the stepper task's `StepperMotion::move_to` with the move
//!   the core sends for the line (board point → joint angles → steps, the
//!   piece count) and its `next_segment`, which cuts the line's pieces
//!   into the planner up to its room (IK and a planner push with replan
//!   per piece) and prepares one segment.
//!
//! `gcode.line.<actuator>.core` is the core's window of that dearest line.
//! A line not answered `ok`, or refused by a stage, is an error.

use core::fmt::Write;
use core::hint::black_box;

use embassy_time::Instant;
use galvo_planner::MarkLimits;
use galvo_planner::blocks::LoopPathPlanner;
use laser_app::command::{Command, GrblLine};
use laser_app::domain::Actuator;
use laser_app::galvo::{GalvoConfig, ScanPhase};
use laser_app::sequencer::{Action, ActionSink, Core, Event, GalvoReadout, Inputs, Line, Readings};
use laser_app::servo::task::{ServoOutcome, ServoRequest};
use laser_app::stepper::{MoveShape, StepperConfig, StepperEvent, StepperMotion, StepperRequest};

use crate::harness::{Bench, Name, window};
use crate::sweep::{Rng, SEED, report_median};

/// Lines tried per actuator.
pub const LINES: u32 = 300;
/// Where every line starts, mm (the end of the queued blocks).
const P0: [f64; 2] = [5.0, 5.0];
/// The blocks queued before each line: a loop from [`P0`] back to it.
const BASE: [&str; 4] = ["G1 X40 Y0 F1200", "G1 X40 Y20", "G1 X0 Y20", "G1 X5 Y5"];

/// What the shell read from the links (an idle galvo loop).
const READINGS: Readings = Readings {
    galvo: GalvoReadout {
        phase: ScanPhase::Idle,
        queued: 0,
        underruns: 0,
        halves: 0,
        refill: None,
    },
    implausible_readings: 0,
};

/// What one event's actions said.
#[derive(Default)]
struct Sink {
    /// The reply's closer: `Some(true)` for `ok`.
    ok: Option<bool>,
    servo_move: Option<u32>,
    stepper_move: Option<StepperRequest>,
    stepper_config: Option<StepperConfig>,
}

impl ActionSink for Sink {
    fn act(&mut self, action: Action) {
        match action {
            Action::Line(Line::Ok) => self.ok = Some(true),
            Action::Line(Line::Error(_) | Line::GrblError(_)) => self.ok = Some(false),
            Action::Servo(ServoRequest::Move { seq, .. }) => self.servo_move = Some(seq),
            Action::Stepper(r @ StepperRequest::MoveTo { .. }) => self.stepper_move = Some(r),
            Action::ConfigureStepper(c) => self.stepper_config = Some(c),
            other => {
                black_box(other);
            }
        }
    }
}

/// The core and the time and links it is driven with.
#[derive(Clone)]
struct Rig {
    core: Core,
    ms: u64,
}

impl Rig {
    fn on(&mut self, event: Event) -> Sink {
        let inputs = Inputs {
            now: Instant::from_millis(self.ms),
            galvo_room: Some(8),
            galvo_bisection: false,
            stepper_attached: true,
        };
        let mut sink = Sink::default();
        self.core.on(inputs, event, &mut sink);
        sink
    }

    fn command(&mut self, command: Command) -> Sink {
        self.on(Event::Command {
            command,
            readings: READINGS,
        })
    }

    /// Sends a grbl line; `Err` unless it is answered `ok`.
    fn line(&mut self, text: &str) -> Result<Sink, &'static str> {
        let line = GrblLine::new(text).ok_or("line too long")?;
        let sink = self.command(Command::Grbl(line));
        match sink.ok {
            Some(true) => Ok(sink),
            _ => Err("line not answered ok"),
        }
    }

    /// Confirms servo and stepper moves and runs the core's ticks until
    /// nothing is pending (at most `steps` events).
    fn settle(&mut self, mut sink: Sink, steps: u32) {
        for _ in 0..steps {
            self.ms += 1;
            sink = if let Some(seq) = sink.servo_move.take() {
                self.on(Event::Servo(ServoOutcome::Arrived {
                    seq,
                    yaw_tenths: 0,
                    pitch_tenths: 0,
                }))
            } else if let Some(StepperRequest::MoveTo { seq, .. }) = sink.stepper_move.take() {
                self.on(Event::Stepper(StepperEvent::Arrived { seq, steps: [0, 0] }))
            } else if let Some(deadline) = self.core.dwell_deadline() {
                self.ms = self.ms.max(deadline.as_millis());
                self.on(Event::DwellEnded)
            } else {
                return;
            };
        }
    }

    /// A core on `actuator`, at rest at [`P0`]; the stepper's config and
    /// the move the core sent it to [`P0`].
    fn at_rest(actuator: Actuator) -> Result<(Self, Setup), &'static str> {
        let mut rig = Self {
            core: Core::new(Instant::from_millis(0)),
            ms: 1,
        };
        let target = rig.command(Command::Target(actuator));
        if target.ok != Some(true) {
            return Err("target refused");
        }
        let start = rig.line("G0 X5 Y5")?;
        let setup = Setup {
            config: target.stepper_config,
            to_p0: start.stepper_move,
        };
        rig.settle(start, 64);
        Ok((rig, setup))
    }

    /// This rig with the [`BASE`] blocks queued.
    fn queued(&self) -> Result<Self, &'static str> {
        let mut rig = self.clone();
        for text in BASE {
            rig.ms += 1;
            rig.line(text)?;
        }
        Ok(rig)
    }
}

/// What the stepper's stage is set up from.
struct Setup {
    config: Option<StepperConfig>,
    to_p0: Option<StepperRequest>,
}

/// A random line from [`P0`] and its end (and arc centre), mm.
#[derive(Clone, Copy, Default)]
struct Input {
    /// 0: G0, 1: G1, 2: G2, 3: G3.
    g: u8,
    end: [f64; 2],
    centre: [f64; 2],
    feed: u32,
}

impl Input {
    fn random(rng: &mut Rng, i: u32) -> Self {
        let coord = |rng: &mut Rng| libm::round(rng.range(-50.0, 50.0) * 1000.0) / 1000.0;
        let feed = 100 + rng.below(2900);
        match i % 3 {
            0 | 1 => Self {
                g: (i % 3) as u8,
                end: [coord(rng), coord(rng)],
                centre: [0.0; 2],
                feed,
            },
            _ => {
                let ccw = rng.below(2) == 1;
                let r = rng.range(2.0, 25.0);
                let a = rng.range(-3.1, 3.1);
                let centre = [P0[0] + r * libm::cos(a), P0[1] + r * libm::sin(a)];
                let a0 = a + core::f64::consts::PI;
                let sweep = rng.range(0.3, 5.0);
                let a1 = if ccw { a0 + sweep } else { a0 - sweep };
                let round = |v: f64| libm::round(v * 1000.0) / 1000.0;
                Self {
                    g: if ccw { 3 } else { 2 },
                    end: [
                        round(centre[0] + r * libm::cos(a1)),
                        round(centre[1] + r * libm::sin(a1)),
                    ],
                    centre: [round(centre[0]), round(centre[1])],
                    feed,
                }
            }
        }
    }

    /// The line's text.
    fn text(&self, buf: &mut Text) {
        buf.len = 0;
        let _ = write!(buf, "G{} X{:.3} Y{:.3}", self.g, self.end[0], self.end[1]);
        if self.g >= 2 {
            let _ = write!(
                buf,
                " I{:.3} J{:.3}",
                self.centre[0] - P0[0],
                self.centre[1] - P0[1]
            );
        }
        if self.g >= 1 {
            let _ = write!(buf, " F{}", self.feed);
        }
    }
}

/// A line's text without an allocator.
struct Text {
    buf: [u8; 64],
    len: usize,
}

impl Text {
    fn as_str(&self) -> &str {
        self.buf
            .get(..self.len)
            .and_then(|s| core::str::from_utf8(s).ok())
            .unwrap_or("")
    }
}

impl Write for Text {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let end = self.len + s.len();
        self.buf
            .get_mut(self.len..end)
            .ok_or(core::fmt::Error)?
            .copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// The three rows.
pub fn gcode_lines(b: &mut Bench) {
    for actuator in [Actuator::Gimbal, Actuator::Galvo, Actuator::Stepper] {
        let id = match actuator {
            Actuator::Gimbal => "gcode.line.gimbal",
            Actuator::Galvo => "gcode.line.galvo",
            _ => "gcode.line.stepper",
        };
        if let Err(e) = sweep(b, id, actuator) {
            b.fail(id, e);
        }
    }
}

/// [`LINES`] random lines on `actuator`; reports the dearest.
fn sweep(b: &mut Bench, id: &str, actuator: Actuator) -> Result<(), &'static str> {
    let (rest, setup) = Rig::at_rest(actuator)?;
    let busy = rest.queued()?;
    let stages = Stages::new(actuator, &rest, setup)?;
    let mut rng = Rng::new(SEED ^ 0x6C0DE);
    let mut text = Text {
        buf: [0; 64],
        len: 0,
    };
    let mut worst = ((0u32, 0u32), Input::default());
    let mut figures = [(0u32, 1u32); LINES as usize];
    for (i, slot) in (0..LINES).zip(figures.iter_mut()) {
        let input = Input::random(&mut rng, i);
        input.text(&mut text);
        let ticks = match measure(&busy, &stages, &input, text.as_str()) {
            Ok(t) => t,
            Err(e) => {
                let _ = writeln!(b.out, "error {id} line {i} {e}: {}", text.as_str());
                b.failures += 1;
                continue;
            }
        };
        *slot = (ticks.1, 1);
        if ticks.1 > worst.0.1 {
            worst = (ticks, input);
        }
    }
    b.report(id, worst.0.1, 1);
    report_median(b, id, &mut figures);
    let mut core_id = Name::new();
    core_id.set(id, ".core");
    b.report(core_id.as_str(), worst.0.0, 1);
    worst.1.text(&mut text);
    let _ = writeln!(b.out, "worst {id} {LINES} {}", text.as_str());
    b.out.flush();
    Ok(())
}

/// The actuator's planning stage, set up with the [`BASE`] blocks.
#[allow(clippy::large_enum_variant)] // One, on the bench's stack.
enum Stages {
    Gimbal,
    Galvo(LoopPathPlanner),
    Stepper {
        motion: StepperMotion,
        /// The core at rest at [`P0`] (for the move it sends a line).
        rest: Rig,
    },
}

impl Stages {
    fn new(actuator: Actuator, rest: &Rig, setup: Setup) -> Result<Self, &'static str> {
        match actuator {
            Actuator::Galvo => {
                let c = GalvoConfig::default();
                let limits = MarkLimits {
                    speed_mm_s: c.mark_speed_mm_s,
                    accel_mm_s2: c.mark_accel_mm_s2,
                    junction_deviation_mm: c.junction_deviation_mm,
                    ts_s: c.sample_period_s,
                };
                let mut planner =
                    LoopPathPlanner::new(limits, [40.0, 0.0]).map_err(|_| "path planner")?;
                planner.set_feed_mm_s(20.0).map_err(|_| "feed")?;
                for p in [[40.0, 20.0], [0.0, 20.0], P0] {
                    planner.line_to(p).map_err(|_| "base stroke")?;
                }
                Ok(Self::Galvo(planner))
            }
            Actuator::Stepper => {
                // The core sends its config when it is not the default
                // settings' one (it is here).
                let config = setup.config.unwrap_or_default();
                let mut motion = StepperMotion::new(config).map_err(|_| "stepper motion")?;
                // A feed line to the core's point for [`P0`], cut into
                // the planner: the line's pieces are planned behind it.
                let Some(StepperRequest::MoveTo { seq, point, .. }) = setup.to_p0 else {
                    return Err("no stepper move to P0");
                };
                motion
                    .move_to(seq, point, MoveShape::Line, Some(20.0))
                    .map_err(|_| "base move")?;
                black_box(motion.next_segment());
                Ok(Self::Stepper {
                    motion,
                    rest: rest.clone(),
                })
            }
            _ => Ok(Self::Gimbal),
        }
    }
}

/// Ticks of one line through the windows of its path (module docs): the
/// core's window and the sum of all.
fn measure(
    busy: &Rig,
    stages: &Stages,
    input: &Input,
    text: &str,
) -> Result<(u32, u32), &'static str> {
    let mut rig = busy.clone();
    rig.ms += 1;
    let line = GrblLine::new(text).ok_or("line too long")?;
    let mut sink = Sink::default();
    let mut ticks = window(|| sink = rig.command(Command::Grbl(black_box(line))));
    if sink.ok != Some(true) {
        return Err("line not answered ok");
    }
    let core_ticks = ticks;
    match stages {
        Stages::Gimbal => {
            let deadline = rig.core.dwell_deadline().ok_or("not streaming")?;
            rig.ms = rig.ms.max(deadline.as_millis());
            ticks += window(|| black_box(rig.on(Event::DwellEnded)));
        }
        Stages::Galvo(base) => {
            let mut planner = base.clone();
            let mut added = Ok(());
            ticks += window(|| {
                added = match input.g {
                    0 => planner.move_to(black_box(input.end)),
                    1 => planner.line_to(black_box(input.end)),
                    g => planner.arc_to(black_box(input.end), input.centre, g == 3),
                };
            });
            added.map_err(|_| "path planner refused the line")?;
        }
        Stages::Stepper { motion, rest } => {
            let mut at_p0 = rest.clone();
            let Some(StepperRequest::MoveTo {
                seq,
                point,
                shape,
                feed_mm_s,
            }) = at_p0.line(text)?.stepper_move
            else {
                return Err("no stepper move");
            };
            let mut motion = motion.clone();
            let mut taken = Ok(false);
            ticks += window(|| {
                taken = motion.move_to(seq, point, shape, feed_mm_s);
                black_box(motion.next_segment());
            });
            taken.map_err(|_| "stepper refused the move")?;
        }
    }
    Ok((core_ticks, ticks))
}
