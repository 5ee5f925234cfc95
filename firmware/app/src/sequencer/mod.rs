//! The sequencer task: receives commands from the command channel, runs
//! patterns point by point (aim → servo move → arrival → dwell → next),
//! and answers each command with exactly one closing reply.
//!
//! What it does is decided by a pure state machine, [`Core`] (no `async`,
//! no I/O: an [`Event`] in, [`Action`]s out); [`Sequencer`] is the thin
//! async shell around it. The shell waits on everything at once — the next
//! command or stop request, the servo task's outcome, the galvo loop's
//! events, the core's dwell deadline and the housekeeping tick — so a new
//! command preempts a running pattern immediately, in any phase; it hands
//! each to the core, applies the actions, and publishes the core's status
//! view on the [`StatusBoard`].

mod commands;
mod controls;
mod drivers;
mod faults;
mod gcode;
mod io;
mod laser;
mod machine;
mod presets;
mod report;
mod run;
mod servo_setup;
mod trace;

use embassy_futures::select::{Either, Either3, Either4, select, select3, select4};
use embassy_time::{Duration, Instant, Timer};

pub use self::drivers::galvo::config_from;
pub use self::gcode::GCODE_RAM_BYTES;
pub use self::laser::{LaserEvent, LaserPower, LaserSwitch, laser_wanted};
pub use self::machine::{Action, ActionSink, Core, Event, GalvoReadout, Inputs, Line, Readings};
use crate::command::{Command, CommandLink};
use crate::galvo::{GalvoLink, GalvoRequest};
use crate::laser_controls::ControlsLink;
use crate::laser_gate::LaserGate;
use crate::log;
use crate::outbound::{LineKind, Origin};
use crate::servo::task::ServoLink;
use crate::settings::Settings;
use crate::status::StatusBoard;
use crate::stepper::{StepperLink, StepperRequest};

/// Where settings are saved (defined with the settings; named here too,
/// as the sequencer's store).
pub use crate::settings::store::SettingsStore;

/// Period of the housekeeping tick (liveness for the watchdog).
const HOUSEKEEPING: Duration = Duration::from_millis(250);

/// The sequencer task: the [`Core`] and the links it acts on. Create with
/// [`Sequencer::new`], then [`Sequencer::run`].
pub struct Sequencer<'a, L: LaserSwitch, S: SettingsStore> {
    core: Core,
    io: Io<'a, L, S>,
}

/// The links to the actuators other than the servo gimbal.
#[derive(Clone, Copy)]
pub struct ActuatorLinks<'a> {
    /// The galvo loop's (served only on a board with a galvo DAC).
    pub galvo: &'a GalvoLink,
    /// The stepper task's (served only on a board with stepper outputs).
    pub stepper: &'a StepperLink,
    /// The laser controls task's (served only on a board with the
    /// controls).
    pub controls: &'a ControlsLink,
}

/// What the core's actions act on.
struct Io<'a, L: LaserSwitch, S: SettingsStore> {
    link: &'a CommandLink,
    servo: &'a ServoLink,
    /// The galvo link (whether a galvo loop serves it is its
    /// [`GalvoLink::attached`]).
    galvo: &'a GalvoLink,
    /// The stepper link (whether a stepper task serves it is its
    /// [`StepperLink::is_attached`]).
    stepper: &'a StepperLink,
    /// The laser controls' link (`arm` requests, their state).
    controls: &'a ControlsLink,
    status: &'a StatusBoard,
    laser: L,
    /// The master laser gate: closed at once by every stop, opened only
    /// for a run that draws.
    gate: &'a LaserGate,
    /// Gate generation of the current run (since the core last closed
    /// it): the gimbal laser opens the gate only for it.
    generation: u32,
    /// Whether the gimbal laser output is on.
    lit: bool,
    /// The power the gimbal laser runs at while lit.
    power: LaserPower,
    store: S,
    /// What the actions applied last ask to follow.
    follow_up: FollowUp,
    /// The gate refused to light the gimbal laser (the core is told once
    /// the event and its follow-ups are done).
    refused: bool,
}

/// What the shell does after applying the actions of one event.
#[derive(Debug, Clone, Copy, PartialEq)]
enum FollowUp {
    /// Wait for the next event.
    Nothing,
    /// Yield, then continue the pattern check.
    Yield,
    /// Save the settings, then report the result.
    Save,
    /// Save (or clear) a preset, then report the result.
    SavePreset(u8, Option<crate::domain::PointCm>),
    /// Read a preset, then hand it to the core.
    LoadPreset(u8),
}

impl<'a, L: LaserSwitch, S: SettingsStore> Sequencer<'a, L, S> {
    /// A sequencer with settings loaded from `store` (defaults, with a
    /// warning, when the record is missing, old or corrupt). `gate` is the
    /// master laser gate shared with the galvo loop and the laser pin;
    /// `galvo` the link to the galvo loop, if one runs.
    pub async fn new(
        link: &'a CommandLink,
        servo: &'a ServoLink,
        actuators: ActuatorLinks<'a>,
        status: &'a StatusBoard,
        mut laser: L,
        gate: &'a LaserGate,
        mut store: S,
    ) -> Self {
        laser.set(LaserPower::OFF);
        let generation = gate.close();
        let mut record = [0u8; crate::settings::MAX_RECORD_LEN];
        let n = store.load(&mut record).await;
        let io = Io {
            link,
            servo,
            galvo: actuators.galvo,
            stepper: actuators.stepper,
            controls: actuators.controls,
            status,
            laser,
            gate,
            generation,
            lit: false,
            power: LaserPower::FULL,
            store,
            follow_up: FollowUp::Nothing,
            refused: false,
        };
        Self::started(io, record.get(..n).unwrap_or(&[]))
    }

    /// The sequencer with the settings of `record` applied. Not inlined:
    /// its copies of the settings (record, core, event) stay out of the
    /// task's frame.
    #[inline(never)]
    fn started(io: Io<'a, L, S>, record: &[u8]) -> Self {
        let mut sequencer = Self {
            core: Core::new(Instant::now()),
            io,
        };
        sequencer.load(record);
        sequencer.io.status.publish(sequencer.core.status());
        sequencer
    }

    /// Applies the settings of `record`. Not inlined: the settings'
    /// copies (record, event) stay out of the start-up frame.
    #[inline(never)]
    fn load(&mut self, record: &[u8]) {
        // The galvo loop starts with the loaded parameters and laser mode
        // (loading asks for no follow-up: no reply, check or save).
        let loaded = Settings::load_record(record);
        let _ = self.dispatch(Event::SettingsLoaded(loaded));
    }

    /// Current settings.
    pub fn settings(&self) -> &Settings {
        self.core.settings()
    }

    /// Runs forever.
    pub async fn run(&mut self) -> ! {
        let mut housekeeping = Instant::now() + HOUSEKEEPING;
        loop {
            let event = self.next_event(housekeeping).await;
            if matches!(event, Event::Tick) {
                housekeeping = Instant::now() + HOUSEKEEPING;
            }
            let mut follow_up = self.dispatch(event);
            while follow_up != FollowUp::Nothing {
                follow_up = self.follow(follow_up).await;
            }
            self.io.status.publish(self.core.status());
        }
    }

    /// Waits for the next event.
    async fn next_event(&self, housekeeping: Instant) -> Event {
        let io = &self.io;
        let deadline = self.core.dwell_deadline();
        let timer = async {
            match deadline {
                Some(at) => Timer::at(at).await,
                None => core::future::pending::<()>().await,
            }
        };
        // Realtime bytes first: the console sends them before the lines
        // that follow them in the host's input, so a line typed after a
        // soft reset (even in the same write) runs in the new session.
        let command = select(
            io.link.realtime.receive(),
            select(io.link.commands.receive(), io.link.stop_request.wait()),
        );
        let event = select4(
            command,
            io.servo.outcomes.receive(),
            timer,
            select3(
                Timer::at(housekeeping),
                io.galvo.events.receive(),
                io.stepper.events.receive(),
            ),
        )
        .await;
        match event {
            Either4::First(Either::First(request)) => Event::Realtime(request),
            Either4::First(Either::Second(Either::First(command))) => {
                log::debug!("command: {:?}", command);
                if let Command::Trace(on) = command {
                    io.link.set_tracing(on);
                }
                Event::Command {
                    command,
                    readings: io.readings(),
                }
            }
            Either4::First(Either::Second(Either::Second(()))) => Event::StopRequest,
            Either4::Second(outcome) => Event::Servo(outcome),
            Either4::Third(()) => Event::DwellEnded,
            Either4::Fourth(Either3::First(())) => Event::Tick,
            Either4::Fourth(Either3::Second(event)) => Event::Galvo(event),
            Either4::Fourth(Either3::Third(event)) => Event::Stepper(event),
        }
    }

    /// Hands `event` to the core and applies its actions (a gate found
    /// lost meanwhile is handed on at once); returns what must follow.
    /// Synchronous, and an event is never held across an await: the
    /// task's future stays small.
    fn dispatch(&mut self, event: Event) -> FollowUp {
        let mut event = event;
        let galvo = self.io.galvo;
        loop {
            let inputs = Inputs {
                now: Instant::now(),
                galvo_room: galvo.attached().then(|| galvo.requests.free_capacity()),
                galvo_bisection: galvo.plans_bisection(),
                stepper_attached: self.io.stepper.is_attached(),
            };
            // The stepper's speed over its block's cruise speed, ‰.
            self.core.jobs.stepper.speed_permille = self.io.stepper.speed_permille();
            self.core.note_laser_controls(self.io.controls.view());
            self.core.on(inputs, event, &mut self.io);
            let follow_up = core::mem::replace(&mut self.io.follow_up, FollowUp::Nothing);
            if follow_up != FollowUp::Nothing {
                return follow_up;
            }
            if !(core::mem::take(&mut self.io.refused) || self.io.gate_lost()) {
                return FollowUp::Nothing;
            }
            event = Event::GateLost;
        }
    }

    /// Does what the last actions asked for (yield during a pattern check,
    /// save the settings, save or read a preset) and hands the result to the core.
    async fn follow(&mut self, follow_up: FollowUp) -> FollowUp {
        let event = match follow_up {
            FollowUp::Nothing => return FollowUp::Nothing,
            FollowUp::Yield => {
                embassy_futures::yield_now().await;
                Event::CheckStep
            }
            FollowUp::Save => {
                let record = self.core.settings().to_record();
                Event::Saved(self.io.store.save(&record).await)
            }
            FollowUp::SavePreset(n, point) => {
                Event::Saved(self.io.store.save_preset(n, point).await)
            }
            FollowUp::LoadPreset(n) => Event::PresetLoaded {
                n,
                point: self.io.store.load_preset(n).await,
            },
        };
        self.dispatch(event)
    }
}

impl<L: LaserSwitch, S: SettingsStore> Io<'_, L, S> {
    /// What a command may need from the links.
    fn readings(&self) -> Readings {
        use core::sync::atomic::Ordering::Relaxed;
        let galvo = self.galvo;
        let (phase, queued) = galvo.state();
        Readings {
            galvo: GalvoReadout {
                phase,
                queued,
                underruns: galvo.underruns.load(Relaxed),
                halves: galvo.halves.load(Relaxed),
                refill: galvo.refill(),
            },
            implausible_readings: self.servo.implausible_readings.load(Relaxed),
        }
    }

    /// Whether the gimbal laser is on but the gate no longer lets it
    /// shine (the galvo loop closed it).
    fn gate_lost(&self) -> bool {
        self.lit && !self.gate.open(self.generation)
    }

    /// Switches the gimbal laser: on only through the gate.
    fn set_laser(&mut self, on: bool) {
        let lit = on && self.gate.open(self.generation);
        self.refused |= on && !lit;
        if lit != self.lit {
            let power = if lit { self.power } else { LaserPower::OFF };
            self.laser.set(power);
            if self.link.tracing() {
                trace::laser(self.link, Instant::now().as_micros(), power);
            }
            self.lit = lit;
            log::info!("laser {}", if lit { "on" } else { "off" });
        }
    }

    /// The gimbal laser's power while lit (applied at once when it is).
    fn set_power(&mut self, power: LaserPower) {
        let changed = self.power != power;
        self.power = power;
        if self.lit {
            self.laser.set(power);
            if changed && self.link.tracing() {
                trace::laser(self.link, Instant::now().as_micros(), power);
            }
        }
    }
}

impl<L: LaserSwitch, S: SettingsStore> ActionSink for Io<'_, L, S> {
    fn act(&mut self, action: Action) {
        match action {
            Action::Servo(request) => {
                // Newest request wins: drop one the servo task has not
                // taken yet.
                let _ = self.servo.requests.try_receive();
                let _ = self.servo.requests.try_send(request);
            }
            Action::Galvo(GalvoRequest::Stop) => {
                while self.galvo.requests.try_receive().is_ok() {}
                let _ = self.galvo.requests.try_send(GalvoRequest::Stop);
            }
            Action::Galvo(request) => {
                if self.galvo.requests.try_send(request).is_err() {
                    log::warning!("galvo: request queue full");
                }
            }
            Action::ConfigureGalvo(config) => self.galvo.config.signal(config),
            Action::AllowGalvoLaser(allowed) => self.galvo.allow_laser(allowed),
            // At once, not through the stepper task's queue.
            Action::Stepper(StepperRequest::Halt) => self.stepper.halt(),
            Action::Stepper(StepperRequest::FeedOverride { percent }) => {
                self.stepper.set_feed_override(percent);
            }
            Action::Stepper(request) => {
                if self.stepper.requests.try_send(request).is_err() {
                    log::warning!("stepper: request queue full");
                }
            }
            Action::ConfigureStepper(config) => self.stepper.config.signal(config),
            Action::CloseGate => self.generation = self.gate.close(),
            Action::ShutGate => {
                self.gate.shut();
            }
            Action::ArmLaser { delay_ms } => self.controls.arm.signal(delay_ms),
            Action::GimbalLaser(on) => self.set_laser(on),
            Action::GimbalPower(power) => self.set_power(power),
            Action::Note(event) => {
                self.laser.note(event);
                if self.link.tracing() {
                    trace::event(self.link, Instant::now().as_micros(), event);
                }
            }
            Action::Line(line) => {
                let outbound = &self.link.outbound;
                let _ = match &line {
                    Line::Data(text) => outbound.push(LineKind::Data, text),
                    Line::Notice(text) => outbound.push(LineKind::Notice, text),
                    Line::Push(text) => outbound.push_from(Origin::Direct, LineKind::Data, text),
                    Line::Ok => outbound.push(LineKind::Ok, ""),
                    Line::Error(text) => outbound.push(LineKind::Error, text),
                    Line::GrblError(error) => outbound.push_fmt(
                        LineKind::GrblError,
                        format_args!("{}", u32::from(error.code())),
                    ),
                };
            }
            Action::Save => self.follow_up = FollowUp::Save,
            Action::SavePreset { n, point } => self.follow_up = FollowUp::SavePreset(n, point),
            Action::LoadPreset(n) => self.follow_up = FollowUp::LoadPreset(n),
            Action::Yield => self.follow_up = FollowUp::Yield,
        }
    }
}
