//! The sequencer task body: an event-driven state machine that receives
//! commands from the command channel, runs patterns point by point (aim →
//! servo move → arrival → dwell → next), and answers each command with
//! exactly one closing reply.
//!
//! It waits on three things at once — the next command, the servo task's
//! outcome, and its own dwell deadline — so a new command preempts a
//! running pattern immediately, in any phase.

mod commands;
mod faults;
mod galvo;
mod laser;
pub mod targets;

use embassy_futures::select::{Either, Either4, select, select4};
use embassy_time::{Duration, Instant, Timer};

pub use self::laser::{LaserEvent, LaserSwitch, laser_wanted};
use self::targets::{Aim, PathCursor, Target};
use crate::command::{Actuator, AimModel, CommandLink, Pattern};
use crate::galvo::GalvoLink;
use crate::laser_gate::LaserGate;
use crate::log;
use crate::servo::task::{ServoLink, ServoOutcome, ServoRequest};
use crate::settings::{RecordError, Settings};
use crate::status::{Activity, Phase, StatusBoard};
use crate::text::Fixed;

/// Where settings are saved (defined with the settings; named here too,
/// as the sequencer's store).
pub use crate::settings::store::SettingsStore;

/// Period of the housekeeping tick (liveness for the watchdog).
const HOUSEKEEPING: Duration = Duration::from_millis(250);

/// The sequencer's state. Create with [`Sequencer::new`], then
/// [`Sequencer::run`].
pub struct Sequencer<'a, L: LaserSwitch, S: SettingsStore> {
    link: &'a CommandLink,
    servo: &'a ServoLink,
    /// The galvo loop, when this build has one.
    galvo: Option<&'a GalvoLink>,
    status: &'a StatusBoard,
    laser: L,
    /// The master laser gate: closed at once by every stop, opened only
    /// for a run that draws.
    gate: &'a LaserGate,
    /// Gate generation of the current run (since the last close): the
    /// gimbal laser opens the gate only for it.
    gate_generation: u32,
    store: S,
    settings: Settings,
    model: AimModel,
    /// Which actuator(s) draw.
    actuator: Actuator,
    booted_at: Instant,
    /// Current activity and where it is.
    run: Option<Run>,
    /// Request number of the servo move in flight.
    next_seq: u32,
    /// Servos known dead (faulted, not yet answering again), and whether
    /// the gimbal laser waits for a confirmed arrival after a fault.
    faults: faults::ServoFaults,
    /// Last aim sent to the servos.
    last_aim: Option<(Target, Aim)>,
    /// Last measured servo angles, 0.1°.
    measured: Option<(i16, i16)>,
    laser_on: bool,
}

/// An active pattern or goto.
#[derive(Debug, Clone, Copy)]
struct Run {
    /// What runs (`None`: a single goto / grid target).
    pattern: Option<Pattern>,
    /// The goto target when `pattern` is `None`.
    single: Option<Target>,
    once: bool,
    /// Index of the current point within the pass.
    index: usize,
    /// A path's interpolation state in the current pass (next point in
    /// O(1)); `None` for grid patterns (looked up by index in O(1)), a
    /// goto, and paths the galvo marks itself.
    path: Option<PathCursor>,
    /// Completed passes.
    pass: u32,
    phase: Phase,
    /// Move in flight.
    seq: u32,
    /// End of the dwell.
    dwell_until: Option<Instant>,
    /// The gimbal has not finished the current point (move + dwell).
    gimbal_busy: bool,
    /// The galvo has not reported the current point done.
    galvo_busy: bool,
    /// Request number of the galvo point in flight.
    galvo_seq: u32,
}

impl<'a, L: LaserSwitch, S: SettingsStore> Sequencer<'a, L, S> {
    /// A sequencer with settings loaded from `store` (defaults, with a
    /// warning, when the record is missing, old or corrupt). `gate` is the
    /// master laser gate shared with the galvo loop and the laser pin.
    pub async fn new(
        link: &'a CommandLink,
        servo: &'a ServoLink,
        galvo: Option<&'a GalvoLink>,
        status: &'a StatusBoard,
        mut laser: L,
        gate: &'a LaserGate,
        mut store: S,
    ) -> Self {
        laser.set(false);
        let gate_generation = gate.close();
        let mut record = [0u8; crate::settings::MAX_RECORD_LEN];
        let n = store.load(&mut record).await;
        let settings = match Settings::load_record(record.get(..n).unwrap_or(&[])) {
            Ok(loaded) => {
                log::info!(
                    "settings loaded from flash ({:?} layout; {} unknown entries skipped, {} parameters defaulted)",
                    loaded.layout,
                    loaded.unknown,
                    loaded.defaulted
                );
                loaded.settings
            }
            Err(RecordError::Missing) => {
                log::info!("no saved settings, using defaults");
                Settings::default()
            }
            Err(e) => {
                log::warning!("saved settings unusable ({:?}), using defaults", e);
                Settings::default()
            }
        };
        status.update(|s| s.activity = Activity::Idle);
        let mut sequencer = Self {
            link,
            servo,
            galvo,
            status,
            laser,
            gate,
            gate_generation,
            store,
            settings,
            model: AimModel::Exact,
            actuator: Actuator::Gimbal,
            booted_at: Instant::now(),
            run: None,
            next_seq: 0,
            faults: faults::ServoFaults::default(),
            last_aim: None,
            measured: None,
            laser_on: false,
        };
        // The galvo loop starts with the loaded parameters and laser mode.
        sequencer.configure_galvo();
        sequencer
    }

    /// Current settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Runs forever.
    pub async fn run(&mut self) -> ! {
        let mut housekeeping = Instant::now() + HOUSEKEEPING;
        loop {
            let dwell_deadline = self.run.and_then(|r| r.dwell_until);
            let timer = async {
                match dwell_deadline {
                    Some(at) => Timer::at(at).await,
                    None => core::future::pending::<()>().await,
                }
            };
            let command = async {
                match select(self.link.commands.receive(), self.link.stop_request.wait()).await {
                    Either::First(command) => Some(command),
                    Either::Second(()) => None,
                }
            };
            let galvo_link = self.galvo.filter(|_| crate::galvo::GALVO_OUTPUT);
            let galvo_event = async {
                match galvo_link {
                    Some(galvo) => galvo.events.receive().await,
                    None => core::future::pending().await,
                }
            };
            let event = select4(
                command,
                self.servo.outcomes.receive(),
                timer,
                select(Timer::at(housekeeping), galvo_event),
            )
            .await;
            match event {
                Either4::First(Some(command)) => {
                    log::debug!("command: {:?}", command);
                    self.handle_command(command).await;
                }
                Either4::First(None) => self.stop("stop button"),
                Either4::Second(outcome) => self.handle_outcome(outcome),
                Either4::Third(()) => self.dwell_finished(),
                Either4::Fourth(Either::First(())) => {
                    housekeeping = Instant::now() + HOUSEKEEPING;
                    self.status
                        .update(|s| s.heartbeat = s.heartbeat.wrapping_add(1));
                }
                Either4::Fourth(Either::Second(event)) => {
                    if crate::galvo::GALVO_OUTPUT {
                        self.handle_galvo_event(event);
                    }
                }
            }
            self.apply_laser();
        }
    }

    /// Starts `run` at its first point.
    fn start(&mut self, mut run: Run) {
        let name = run.pattern.map(|p| p.name()).unwrap_or("goto");
        log::info!("start {} (once={})", name, run.once);
        self.laser.note(laser::LaserEvent::RunStarted);
        run.path = self.path_cursor(run.pattern);
        // Nothing of an earlier run may shine: a new gate generation, and
        // the galvo drops its points and an underrun latch.
        self.close_gate();
        self.run = Some(run);
        self.begin_point();
    }

    /// Stops whatever runs — and, whatever the sequencer thinks runs, the
    /// laser and the galvo loop: the gate closes at once and the loop gets
    /// `Stop`.
    fn stop(&mut self, why: &str) {
        self.laser.note(laser::LaserEvent::Stopped { why });
        self.close_gate();
        if let Some(run) = self.run.take() {
            let name = run.pattern.map(|p| p.name()).unwrap_or("goto");
            log::info!("stop {} ({})", name, why);
        }
        self.publish();
    }

    /// Closes the master laser gate (laser dark from now on, also samples
    /// the galvo DAC already holds) and stops the galvo loop.
    fn close_gate(&mut self) {
        self.gate_generation = self.gate.close();
        self.stop_galvo();
    }

    /// The target of the current point of the run.
    fn current_target(&self) -> Option<Target> {
        let run = self.run?;
        match (run.pattern, run.path) {
            (Some(_), Some(path)) => Some(path.target()),
            (Some(pattern), None) => targets::grid_target(&pattern, run.index, &self.settings),
            (None, _) => run.single,
        }
    }

    /// The cursor at the first point of a pass of `pattern` when the
    /// gimbal draws it point by point (`None` otherwise, or when the path
    /// cannot be interpolated: the run then has no points and stops).
    fn path_cursor(&self, pattern: Option<Pattern>) -> Option<PathCursor> {
        let pattern = pattern?;
        if self.actuator.uses_galvo() {
            return None;
        }
        PathCursor::start(&pattern, &self.settings)?.ok()
    }

    /// Whether the run is a path marked by the galvo alone (one job per
    /// pass instead of point by point).
    fn is_galvo_path_run(&self) -> bool {
        self.actuator.uses_galvo()
            && !self.actuator.uses_gimbal()
            && self
                .run
                .is_some_and(|r| r.pattern.is_some_and(|p| p.is_path()))
    }

    /// Sends the current point to the actuator(s).
    fn begin_point(&mut self) {
        if self.is_galvo_path_run() {
            self.begin_galvo_path();
            return;
        }
        let Some(target) = self.current_target() else {
            self.stop("pattern has no points");
            return;
        };
        // Travel to the first point of a pass (or to a goto target) is off
        // the figure: dark in every laser mode. A later pass of a closed
        // figure starts where the last one ended (arrived there): no travel.
        let approach = self.run.is_some_and(|r| {
            let closed = r.pass > 0 && self.last_aim.is_some_and(|(t, _)| t.point == target.point);
            r.pattern.is_none() || (r.index == 0 && !closed)
        });
        let gimbal_started = !self.actuator.uses_gimbal() || self.begin_gimbal_move(target);
        let galvo_started =
            gimbal_started && (!self.actuator.uses_galvo() || self.begin_galvo_point(target));
        if !(gimbal_started && galvo_started) {
            return;
        }
        let holds = self.run.is_some_and(|r| r.pattern.is_none());
        if let Some(run) = self.run.as_mut() {
            run.phase = if approach {
                Phase::Approaching
            } else {
                Phase::Moving
            };
            run.dwell_until = None;
            run.gimbal_busy = self.actuator.uses_gimbal();
            // A goto's galvo holds the point, laser on, until the next
            // command: nothing to wait for.
            run.galvo_busy = self.actuator.uses_galvo() && !holds;
        }
        self.publish();
        self.point_finished_if_done();
    }

    /// Aims the gimbal at `target` and sends the servo move; on an
    /// unreachable target stops with an error notice.
    fn begin_gimbal_move(&mut self, target: Target) -> bool {
        let aim = match targets::aim(&self.settings, self.model, target.point) {
            Ok(aim) => aim,
            Err(e) => {
                let why = crate::command::reply_text(format_args!("{e}"));
                log::warning!("target unreachable: {}", why.as_str());
                // What happened first: the reason may be cut at the
                // reply line length.
                let name = self
                    .run
                    .and_then(|r| r.pattern)
                    .map_or("goto", |p| p.name());
                self.link.notify(format_args!(
                    "error: {name} stopped, laser off: point ({}, {}) cm unreachable: {}",
                    Fixed::<2>(target.point.x_cm),
                    Fixed::<2>(target.point.y_cm),
                    why
                ));
                self.stop("unreachable target");
                return false;
            }
        };
        let interval_ms = self.move_interval_ms(&aim);
        self.next_seq = self.next_seq.wrapping_add(1);
        let seq = self.next_seq;
        let request = ServoRequest::Move {
            seq,
            yaw_tenths: aim.yaw_wire,
            pitch_tenths: aim.pitch_wire,
            interval_ms,
            ids: (self.settings.yaw.id, self.settings.pitch.id),
            deadband_tenths: (self.settings.deadband_deg * 10.0) as u16,
            ranges_tenths: faults::servo_ranges_tenths(&self.settings),
        };
        // Newest request wins: drop one the servo task has not taken yet.
        let _ = self.servo.requests.try_receive();
        let _ = self.servo.requests.try_send(request);
        self.laser.note(laser::LaserEvent::GimbalMoveSent);
        log::info!(
            "target ({}, {}) cm -> servo {} {} (0.1 deg) over {} ms",
            target.point.x_cm,
            target.point.y_cm,
            aim.yaw_wire,
            aim.pitch_wire,
            interval_ms
        );
        if let Some(run) = self.run.as_mut() {
            run.seq = seq;
        }
        self.last_aim = Some((target, aim));
        true
    }

    /// Travel time for a move at the configured speed, from the largest
    /// joint change (at least 20 ms, the SDK's minimum ramp).
    fn move_interval_ms(&self, aim: &Aim) -> u16 {
        let (from_yaw, from_pitch) = self
            .measured
            .or(self.last_aim.map(|(_, a)| (a.yaw_wire, a.pitch_wire)))
            .unwrap_or((0, 0));
        let travel_tenths = (i32::from(aim.yaw_wire) - i32::from(from_yaw))
            .abs()
            .max((i32::from(aim.pitch_wire) - i32::from(from_pitch)).abs());
        let travel_deg = f64::from(travel_tenths) / 10.0;
        let ms = 1000.0 * travel_deg / self.settings.servo_speed_deg_s;
        (ms as u32).clamp(20, u32::from(u16::MAX)) as u16
    }

    fn handle_outcome(&mut self, outcome: ServoOutcome) {
        match outcome {
            ServoOutcome::Recovered { id } => self.servo_recovered(id),
            ServoOutcome::Arrived {
                seq,
                yaw_tenths,
                pitch_tenths,
            } => {
                self.measured = Some((yaw_tenths, pitch_tenths));
                // Both servos answered and arrived: they are alive.
                self.faults
                    .arrived(self.settings.yaw.id, self.settings.pitch.id);
                let Some(run) = self.run.as_mut().filter(|r| r.seq == seq) else {
                    return;
                };
                run.phase = Phase::Dwelling;
                self.laser.note(laser::LaserEvent::GimbalArrived);
                let dwell = if run.pattern.is_some_and(|p| p.is_path()) {
                    0.0
                } else {
                    self.settings.dwell_ms
                };
                run.dwell_until =
                    Some(Instant::now() + Duration::from_micros((dwell * 1000.0) as u64));
                log::info!("arrived (servo {} {})", yaw_tenths, pitch_tenths);
                self.publish();
            }
            ServoOutcome::Fault { seq, id, fault } => self.servo_fault(seq, id, fault),
            ServoOutcome::Superseded { .. } => {}
        }
    }

    /// The dwell on the current point ended: next point, next pass, or done.
    fn dwell_finished(&mut self) {
        if let Some(run) = self.run.as_mut() {
            run.dwell_until = None;
            run.gimbal_busy = false;
        }
        self.point_finished_if_done();
    }

    /// When every actuator is done with the current point: the next
    /// point, the next pass, the end — or, for a goto, holding.
    fn point_finished_if_done(&mut self) {
        let Some(mut run) = self.run else { return };
        if run.gimbal_busy || run.galvo_busy {
            return;
        }
        let Some(pattern) = run.pattern else {
            // A goto holds its point until the next command.
            run.phase = Phase::Holding;
            self.run = Some(run);
            self.publish();
            return;
        };
        run.index += 1;
        let more = match run.path.as_mut() {
            Some(path) => path.advance(),
            None => {
                !self.is_galvo_path_run()
                    && targets::grid_target(&pattern, run.index, &self.settings).is_some()
            }
        };
        if !more {
            run.pass += 1;
            run.index = 0;
            if run.once {
                self.run = Some(run);
                self.stop("pattern complete");
                return;
            }
            // A new pass takes the path parameters as they are now.
            run.path = self.path_cursor(Some(pattern));
        }
        self.run = Some(run);
        self.begin_point();
    }

    /// Switches the laser to what the state calls for.
    fn apply_laser(&mut self) {
        let phase = self.run.map(|r| r.phase);
        // The galvo's laser is switched per sample by the galvo loop; this
        // is the gimbal's.
        let wanted = self.actuator.uses_gimbal()
            && laser_wanted(
                self.settings.laser_mode,
                phase,
                self.faults.gimbal_laser_blocked(
                    self.settings.yaw.id,
                    self.settings.pitch.id,
                    phase,
                ),
            )
            // Refused when the gate was closed since the run began (a
            // galvo underrun): dark until the run is stopped or restarted.
            && self.gate.open(self.gate_generation);
        if wanted != self.laser_on {
            self.laser.set(wanted);
            self.laser_on = wanted;
            log::info!("laser {}", if wanted { "on" } else { "off" });
            self.publish();
        }
    }

    /// Copies the state to the status board (LEDs, simulator, `status`).
    fn publish(&self) {
        let run = self.run;
        let aim = self.last_aim;
        let laser = self.laser_on;
        let fault = self.faults.first_dead();
        self.status.update(|s| {
            s.activity = match run {
                None => Activity::Idle,
                Some(r) => match r.pattern {
                    Some(p) => Activity::Pattern(p),
                    None => Activity::Goto,
                },
            };
            s.phase = run.map(|r| r.phase);
            s.point_index = run.map(|r| r.index);
            s.pass = run.map(|r| r.pass).unwrap_or(0);
            s.target = aim;
            s.laser_on = laser;
            s.faulty_servo = fault;
        });
    }
}
