//! Assembles a simulation: the simulated board ([`crate::board`]: a
//! simulated USB host's pipes, simulated FashionStar servos on a simulated
//! UART, a recording laser, a simulated galvo DAC, recorded LEDs, button
//! and watchdog) wired to the firmware's task bodies by the same function
//! the target calls ([`laser_app::app::wire`]), and a sampler that follows
//! the laser spot.

use std::cell::RefCell;
use std::rc::Rc;

use std::sync::atomic::Ordering;

use embassy_executor::Spawner;
use laser_app::app::{Links, wire};
use laser_app::command::CommandLink;
use laser_app::galvo::{GalvoConfig, GalvoLink};
use laser_app::laser_controls::ControlsLink;
use laser_app::sequencer::SettingsStore;
use laser_app::servo::task::ServoLink;
use laser_app::status::{Activity, Phase, StatusBoard};
use laser_app::stepper::StepperLink;

use crate::board::{SimBoard, SimSpawner};
use crate::controls::{ControlWiring, SimLaserControls};
use crate::dac::{DacRecording, SimDac};
use crate::executor::{self, RunEnd, TaskKind};
use crate::flash::FlashTiming;
use crate::laser::{GatedLaserPin, recorded_gate};
use crate::panel::{ButtonContacts, PanelRecord, SharedPanel, SimLeds, SimStopButton, SimWatchdog};
use crate::physics::PhysicalGimbal;
use crate::recorder::{Recording, SpotSample};
use crate::servo_model::SimServoBus;
use crate::servo_port::SimServoPort;
use crate::spot::{RecordingLaser, SpotFn, gimbal_spot_cm, spot_sampler};
use crate::stepper::{PanTiltDrivers, SimStepperDrive, StepperGeometry};
use crate::usb_host::{Hands, UsbHost, host_tasks};

mod options;

pub use options::{SimOptions, SimReport};

pub use crate::settings_flash::{
    SETTINGS_FLASH_OFFSET, SETTINGS_SECTOR_BYTES, SETTINGS_SECTORS, SettingsFlash,
    load_settings_record, settings_store,
};

/// Samples per galvo DAC half buffer (1.28 ms at 100 kHz).
pub const GALVO_HALF_LEN: usize = 128;

fn is_idle(status: &StatusBoard) -> bool {
    let s = status.snapshot();
    match s.activity {
        Activity::Idle => true,
        Activity::Goto => s.phase == Some(Phase::Holding),
        Activity::Pattern(_) | Activity::Gcode | Activity::Homing => false,
    }
}

/// One run's world: the links the firmware tasks share and everything the
/// simulated board and host record into.
struct World {
    links: Links,
    host: Rc<UsbHost>,
    recording: Rc<RefCell<Recording>>,
    dac: Rc<RefCell<DacRecording>>,
    panel: SharedPanel,
    button: Rc<ButtonContacts>,
    /// The laser controls' wiring, on a board with them.
    controls: Option<Rc<ControlWiring>>,
    flash: SettingsFlash,
    bus: Rc<RefCell<SimServoBus>>,
    port: Rc<SimServoPort>,
    gimbal: PhysicalGimbal,
    stepper: Rc<RefCell<PanTiltDrivers>>,
    /// Where the pointing actuator's spot is at a time (µs), cm.
    spot: SpotFn,
    /// What crossed the PELCO port.
    pelco: crate::pelco_port::SharedTraffic,
}

impl World {
    /// Links (leaked: one set per run), recordings, flash, servos.
    fn new(options: &SimOptions) -> Self {
        let dac = Rc::new(RefCell::new(DacRecording::default()));
        let links = Links {
            command: Box::leak(Box::new(CommandLink::new())),
            servo: Box::leak(Box::new(ServoLink::new())),
            galvo: Box::leak(Box::new(GalvoLink::new())),
            status: Box::leak(Box::new(StatusBoard::new())),
            gate: recorded_gate(&dac),
            stepper: Box::leak(Box::new(StepperLink::new())),
            controls: Box::leak(Box::new(ControlsLink::new())),
        };
        let fitted =
            options.laser_controls || options.script.iter().any(|s| s.uses_laser_controls());
        let recording = Rc::new(RefCell::new(Recording::default()));
        let gimbal = options.physical;
        let ids = options
            .servo_ids
            .clone()
            .unwrap_or_else(|| vec![gimbal.yaw_id, gimbal.pitch_id]);
        let bus = Rc::new(RefCell::new(SimServoBus::new(&ids, options.slow_factor)));
        let port = Rc::new(SimServoPort::new(
            bus.clone(),
            recording.clone(),
            options.faults.clone(),
            0x5eed,
        ));
        let stepper = Rc::new(RefCell::new(PanTiltDrivers::new(
            options.stepper_timing,
            options.stepper_motor,
        )));
        let spot = pointing_spot(&bus, gimbal, &stepper, options.stepper_geometry);
        Self {
            links,
            stepper,
            spot,
            host: Rc::new(UsbHost::new(options.echo)),
            recording,
            dac,
            panel: SharedPanel::default(),
            button: Rc::new(ButtonContacts::default()),
            controls: fitted.then(|| Rc::new(ControlWiring::bench())),
            flash: boot_settings_flash(options),
            bus,
            port,
            gimbal,
            pelco: Default::default(),
        }
    }

    /// The simulated board (its laser pin records into this run; call
    /// after the gate of [`World::new`]).
    fn board(&self, options: &SimOptions) -> SimBoard {
        let (spot, gimbal) = (self.spot.clone(), self.gimbal);
        let laser = RecordingLaser {
            pin: GatedLaserPin::new(self.recording.clone(), Box::new(move |t_us| spot(t_us))),
            recording: self.recording.clone(),
            bus: self.bus.clone(),
            gimbal,
        };
        let period_ns = (GalvoConfig::default().sample_period_s * 1e9) as u64;
        SimBoard {
            host: self.host.clone(),
            servo_port: self.port.clone(),
            laser,
            settings: settings_store(self.flash.clone()),
            galvo_dac: options.galvo_dac.then(|| {
                let dac = SimDac::new(
                    GALVO_HALF_LEN,
                    period_ns,
                    options.galvo_cost_ns_per_sample,
                    self.dac.clone(),
                );
                if options.galvo_m4_cost {
                    dac
                } else {
                    dac.without_m4_cost()
                }
            }),
            leds: SimLeds(self.panel.clone()),
            stop_button: SimStopButton {
                contacts: self.button.clone(),
                panel: self.panel.clone(),
            },
            watchdog: SimWatchdog(self.panel.clone()),
            laser_controls: self.controls.clone().map(SimLaserControls),
            stepper: options.stepper.then(|| {
                SimStepperDrive::new(
                    self.stepper.clone(),
                    options.stepper_geometry,
                    options.stepper_switches,
                )
            }),
            pelco: pelco_port(options, &self.pelco),
        }
    }

    /// Wires the firmware onto the simulated board (the terminal plugged
    /// into its console), then starts the spot sampler.
    fn start(&self, spawner: Spawner, options: &SimOptions) {
        let host_tasks: Box<dyn FnOnce(&Spawner)> = match &options.pty {
            #[cfg(unix)]
            Some(pty) => Box::new(crate::pty::host_start(self.host.clone(), pty.clone())),
            _ => Box::new(host_tasks(
                options.interactive,
                options.script.clone(),
                self.host.clone(),
                Hands {
                    button: self.button.clone(),
                    bus: self.bus.clone(),
                    controls: self.controls.clone(),
                },
            )),
        };
        let mut sim_spawner = SimSpawner::new(spawner, host_tasks);
        wire(self.board(options), self.links, &mut sim_spawner);
        executor::spawn_task(
            &spawner,
            "spot sampler",
            TaskKind::Simulator,
            spot_sampler(
                self.bus.clone(),
                self.spot.clone(),
                self.recording.clone(),
                self.links.status,
                self.gimbal,
                options.sample_period_us,
            ),
        );
        if let Some(path) = &options.spot_feed {
            executor::spawn_task(
                &spawner,
                "spot feed",
                TaskKind::Simulator,
                crate::spot_feed::spot_feed(
                    path.clone(),
                    self.spot.clone(),
                    self.recording.clone(),
                    options.sample_period_us,
                ),
            );
        }
    }

    /// What the run produced, ended by `end`.
    fn report(self, end: RunEnd) -> SimReport {
        let end_time_us = crate::clock::now_us();
        self.final_spot(end_time_us);
        let settings_flash = self.flash.image();
        SimReport {
            transcript: self.host.transcript.borrow().clone(),
            recording: self.recording.borrow().clone(),
            end,
            end_time_us,
            idle_at_end: is_idle(self.links.status),
            saved_settings: load_settings_record(settings_flash.clone()),
            settings_flash,
            settings_flash_stats: self.flash.stats(),
            dac: self.dac.borrow().clone(),
            galvo_underruns: self.links.galvo.underruns.load(Ordering::Relaxed),
            task_steps: executor::task_steps(),
            panel: self.panel_at_end(end_time_us),
            stepper: self.stepper_at_end(end_time_us),
            laser_controls: self.controls.as_ref().map(|c| c.record()),
            pelco: self.pelco.borrow().clone(),
        }
    }

    /// The drivers with the rotors run on to the end time.
    fn stepper_at_end(&self, end_time_us: u64) -> PanTiltDrivers {
        let mut drivers = self.stepper.borrow().clone();
        for axis in &mut drivers.axes {
            axis.settle(end_time_us * 1000);
        }
        drivers
    }

    /// The trace ends with the laser's final state at the end time.
    fn final_spot(&self, end_time_us: u64) {
        let mut rec = self.recording.borrow_mut();
        if rec.spot.last().is_none_or(|s| s.t_us < end_time_us)
            && let Some((x_cm, y_cm)) = (self.spot)(end_time_us)
        {
            let laser = crate::laser::gimbal_lit();
            let power = rec.power_at(end_time_us);
            rec.spot.push(SpotSample {
                t_us: end_time_us,
                x_cm,
                y_cm,
                laser,
                power,
            });
        }
    }

    fn panel_at_end(&self, end_time_us: u64) -> PanelRecord {
        let mut panel = self.panel.borrow().clone();
        panel.watchdog = panel.watchdog.at_end(end_time_us);
        panel
    }
}

/// The PELCO port the run asks for, on its PTY (none, with the reason on
/// stderr, when the PTY cannot be opened).
fn pelco_port(
    options: &SimOptions,
    traffic: &crate::pelco_port::SharedTraffic,
) -> Option<(crate::pelco_port::PelcoRx, crate::pelco_port::PelcoTx)> {
    #[cfg(unix)]
    if let Some(pty) = &options.pelco_pty {
        return crate::pelco_port::open_on_pty(pty, traffic.clone())
            .map_err(|e| eprintln!("xtask sim: no PELCO port: {e:#}"))
            .ok();
    }
    let _ = (options, traffic);
    None
}

/// The pointing actuator's spot: the stepper's (from its counted steps)
/// once it has stepped, else the gimbal's.
fn pointing_spot(
    bus: &Rc<RefCell<SimServoBus>>,
    gimbal: PhysicalGimbal,
    stepper: &Rc<RefCell<PanTiltDrivers>>,
    geometry: StepperGeometry,
) -> SpotFn {
    let (bus, stepper) = (bus.clone(), stepper.clone());
    Rc::new(move |t_us| {
        let drivers = stepper.borrow();
        if drivers.edges.is_empty() {
            return gimbal_spot_cm(&bus, gimbal, t_us);
        }
        geometry
            .spot_cm(drivers.counted_steps())
            .map(|p| (p.x_cm, p.y_cm))
    })
}

/// Runs one simulation to its end. Independent runs may execute on
/// different threads at the same time.
pub fn run(options: SimOptions) -> SimReport {
    let world = World::new(&options);
    let (host, status) = (world.host.clone(), world.links.status);
    let until_idle = options.until_idle;
    let end = executor::run(
        options.realtime,
        options.max_time_ms * 1000,
        |spawner| world.start(spawner, &options),
        move || host.transcript.borrow().script_done && (!until_idle || is_idle(status)),
    );
    world.report(end)
}

/// The settings flash a run boots with (see [`SimOptions::settings_flash`]).
fn boot_settings_flash(options: &SimOptions) -> SettingsFlash {
    let flash = match (&options.settings_flash, &options.saved_settings) {
        (Some(image), _) => SettingsFlash::from_image(SETTINGS_FLASH_OFFSET, image.clone()),
        (None, Some(record)) => {
            let mut store = settings_store(SettingsFlash::erased(
                SETTINGS_FLASH_OFFSET,
                SETTINGS_SECTORS,
            ));
            if let Err(e) = embassy_futures::block_on(store.save(record)) {
                log::error!("could not preload the settings flash: {e}");
            }
            // A fresh handle: operation counts start at the boot.
            SettingsFlash::from_image(SETTINGS_FLASH_OFFSET, store.into_flash().image())
        }
        (None, None) => SettingsFlash::erased(SETTINGS_FLASH_OFFSET, SETTINGS_SECTORS),
    };
    flash
        .with_power_cut(options.settings_flash_cut)
        .with_timing(FlashTiming::Virtual)
}
