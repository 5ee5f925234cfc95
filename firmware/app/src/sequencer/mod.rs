//! The sequencer task body: an event-driven state machine that receives
//! commands from the command channel, runs patterns point by point (aim →
//! servo move → arrival → dwell → next), and answers each command with
//! exactly one closing reply.
//!
//! It waits on three things at once — the next command, the servo task's
//! outcome, and its own dwell deadline — so a new command preempts a
//! running pattern immediately, in any phase.

mod commands;
mod laser;
pub mod targets;

use embassy_futures::select::{Either, Either4, select, select4};
use embassy_time::{Duration, Instant, Timer};

pub use self::laser::{LaserSwitch, laser_wanted};
use self::targets::{Aim, Target};
use crate::cli::format::Fixed;
use crate::command::{AimModel, CommandLink, Pattern};
use crate::log;
use crate::servo::task::{ServoLink, ServoOutcome, ServoRequest};
use crate::settings::{RecordError, Settings};
use crate::status::{Activity, Phase, StatusBoard};

/// Where settings are saved (a flash sector on the target, memory or a file
/// in the simulator).
#[allow(async_fn_in_trait)]
pub trait SettingsStore {
    /// Reads the saved record into `buf`; returns the bytes read (0 when
    /// nothing is saved).
    async fn load(&mut self, buf: &mut [u8]) -> usize;
    /// Replaces the saved record; `Err` carries a message for the user.
    async fn save(&mut self, record: &[u8]) -> Result<(), &'static str>;
}

/// Period of the housekeeping tick (liveness for the watchdog).
const HOUSEKEEPING: Duration = Duration::from_millis(250);

/// The sequencer's state. Create with [`Sequencer::new`], then
/// [`Sequencer::run`].
pub struct Sequencer<'a, L: LaserSwitch, S: SettingsStore> {
    link: &'a CommandLink,
    servo: &'a ServoLink,
    status: &'a StatusBoard,
    laser: L,
    store: S,
    settings: Settings,
    model: AimModel,
    booted_at: Instant,
    /// Current activity and where it is.
    run: Option<Run>,
    /// Request number of the servo move in flight.
    next_seq: u32,
    /// Servo ids currently faulty.
    faulty_servo: Option<u8>,
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
    /// Completed passes.
    pass: u32,
    phase: Phase,
    /// Move in flight.
    seq: u32,
    /// End of the dwell.
    dwell_until: Option<Instant>,
}

impl<'a, L: LaserSwitch, S: SettingsStore> Sequencer<'a, L, S> {
    /// A sequencer with settings loaded from `store` (defaults, with a
    /// warning, when the record is missing, old or corrupt).
    pub async fn new(
        link: &'a CommandLink,
        servo: &'a ServoLink,
        status: &'a StatusBoard,
        mut laser: L,
        mut store: S,
    ) -> Self {
        laser.set(false);
        let mut record = [0u8; crate::settings::RECORD_LEN];
        let n = store.load(&mut record).await;
        let settings = match Settings::from_record(record.get(..n).unwrap_or(&[])) {
            Ok(s) => {
                log::info!("settings loaded from flash");
                s
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
        Self {
            link,
            servo,
            status,
            laser,
            store,
            settings,
            model: AimModel::Exact,
            booted_at: Instant::now(),
            run: None,
            next_seq: 0,
            faulty_servo: None,
            last_aim: None,
            measured: None,
            laser_on: false,
        }
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
            let event = select4(
                command,
                self.servo.outcomes.receive(),
                timer,
                Timer::at(housekeeping),
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
                Either4::Fourth(()) => {
                    housekeeping = Instant::now() + HOUSEKEEPING;
                    self.status
                        .update(|s| s.heartbeat = s.heartbeat.wrapping_add(1));
                }
            }
            self.apply_laser();
        }
    }

    /// Starts `run` at its first point.
    fn start(&mut self, run: Run) {
        let name = run.pattern.map(|p| p.name()).unwrap_or("goto");
        log::info!("start {} (once={})", name, run.once);
        self.run = Some(run);
        self.faulty_servo = None;
        self.begin_point();
    }

    /// Stops whatever runs.
    fn stop(&mut self, why: &str) {
        if let Some(run) = self.run.take() {
            let name = run.pattern.map(|p| p.name()).unwrap_or("goto");
            log::info!("stop {} ({})", name, why);
        }
        self.publish();
    }

    /// The target of the current point of the run.
    fn current_target(&self) -> Option<Target> {
        let run = self.run?;
        match run.pattern {
            Some(pattern) => targets::pattern_target(&pattern, run.index, &self.settings),
            None => run.single,
        }
    }

    /// Aims at the current point and sends the servo move.
    fn begin_point(&mut self) {
        let Some(target) = self.current_target() else {
            self.stop("pattern has no points");
            return;
        };
        let aim = match targets::aim(&self.settings, self.model, target.point) {
            Ok(aim) => aim,
            Err(e) => {
                let why = crate::command::reply_text(format_args!("{e}"));
                log::warning!("target unreachable: {}", why.as_str());
                self.link.notify(format_args!(
                    "error: target ({}, {}) cm unreachable: {}; stopped, laser off",
                    Fixed::<2>(target.point.x_cm),
                    Fixed::<2>(target.point.y_cm),
                    why
                ));
                self.stop("unreachable target");
                return;
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
        };
        // Newest request wins: drop one the servo task has not taken yet.
        let _ = self.servo.requests.try_receive();
        let _ = self.servo.requests.try_send(request);
        log::info!(
            "target ({}, {}) cm -> servo {} {} (0.1 deg) over {} ms",
            target.point.x_cm,
            target.point.y_cm,
            aim.yaw_wire,
            aim.pitch_wire,
            interval_ms
        );
        if let Some(run) = self.run.as_mut() {
            run.phase = Phase::Moving;
            run.seq = seq;
            run.dwell_until = None;
        }
        self.last_aim = Some((target, aim));
        self.publish();
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
            ServoOutcome::Recovered { id } => {
                if self.faulty_servo == Some(id) {
                    self.faulty_servo = None;
                }
                self.link
                    .notify(format_args!("info: servo {id} answering again"));
                self.publish();
            }
            ServoOutcome::Arrived {
                seq,
                yaw_tenths,
                pitch_tenths,
            } => {
                self.measured = Some((yaw_tenths, pitch_tenths));
                let Some(run) = self.run.as_mut().filter(|r| r.seq == seq) else {
                    return;
                };
                run.phase = Phase::Dwelling;
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
            ServoOutcome::Fault { seq, id, fault } => {
                // A fault of an older, superseded move is stale; any other
                // fault (of the current move, or found by the servo task's
                // health check while dwelling or idle) stops everything.
                if self
                    .run
                    .is_some_and(|r| r.seq != seq && r.phase == Phase::Moving)
                {
                    return;
                }
                self.faulty_servo = Some(id);
                self.link.notify(format_args!(
                    "error: servo {id} fault ({fault:?}); pattern stopped, laser off"
                ));
                self.stop("servo fault");
            }
            ServoOutcome::Present { .. } | ServoOutcome::Superseded { .. } => {}
        }
    }

    /// The dwell on the current point ended: next point, next pass, or done.
    fn dwell_finished(&mut self) {
        let Some(mut run) = self.run else { return };
        run.dwell_until = None;
        let Some(pattern) = run.pattern else {
            // A goto holds its point until the next command.
            run.phase = Phase::Holding;
            self.run = Some(run);
            self.publish();
            return;
        };
        run.index += 1;
        if targets::pattern_target(&pattern, run.index, &self.settings).is_none() {
            run.pass += 1;
            run.index = 0;
            if run.once {
                self.run = Some(run);
                self.stop("pattern complete");
                return;
            }
        }
        self.run = Some(run);
        self.begin_point();
    }

    /// Switches the laser to what the state calls for.
    fn apply_laser(&mut self) {
        let phase = self.run.map(|r| r.phase);
        let wanted = laser_wanted(self.settings.laser_mode, phase, self.faulty_servo.is_some());
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
        let fault = self.faulty_servo;
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
