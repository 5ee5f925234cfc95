//! Assembles a simulation: the firmware's task bodies (console, sequencer,
//! servo task — the same code the target runs) wired to a simulated USB
//! host, simulated FashionStar servos on a simulated UART, a recording
//! laser, and a sampler that follows the laser spot.

use std::cell::RefCell;
use std::rc::Rc;

use embassy_time::Timer;
use std::sync::atomic::Ordering;

use laser_app::command::CommandLink;
use laser_app::galvo::{GalvoConfig, GalvoLink, GalvoLoop};
use laser_app::sequencer::{LaserEvent, LaserSwitch, Sequencer, SettingsStore};
use laser_app::servo::task::{ServoBus, ServoBusConfig, ServoLink};
use laser_app::settings::store::FlashSettingsStore;
use laser_app::status::{Activity, Phase, StatusBoard};
use sequential_storage::map::MapConfig;

use crate::dac::{DacRecording, SimDac};
use crate::executor::TaskKind;
use crate::executor::{self, RunEnd};
use crate::flash::{FlashStats, FlashTiming, PowerCut, SimFlash};
use crate::laser::{GatedLaserPin, recorded_gate};
use crate::physics::PhysicalGimbal;
use crate::recorder::{
    DwellRecord, EventRecord, Recording, SequencerEvent, ServoSample, ServoState, SpotSample,
};
use crate::script::Step;
use crate::servo_model::SimServoBus;
use crate::servo_port::{BusFaults, PortHandle, SimServoPort};
use crate::usb_host::{Transcript, UsbHost, interactive_task, script_task, terminal_task};

/// Samples per galvo DAC half buffer (1.28 ms at 100 kHz).
pub const GALVO_HALF_LEN: usize = 128;

/// Bytes per sector of the settings flash (the STM32F407's sectors 10 and
/// 11 are 128 KiB each).
pub const SETTINGS_SECTOR_BYTES: usize = 128 * 1024;
/// The settings flash as the target has it: sectors 10 and 11.
pub type SettingsFlash = SimFlash<SETTINGS_SECTOR_BYTES>;
/// Offset of the settings sectors from the start of flash (0x080C_0000).
pub const SETTINGS_FLASH_OFFSET: u32 = 0x000C_0000;
/// Sectors the settings use.
pub const SETTINGS_SECTORS: usize = 2;

/// The settings store over `flash`, laid out as on the target.
pub fn settings_store(flash: SettingsFlash) -> FlashSettingsStore<SettingsFlash> {
    FlashSettingsStore::new(
        flash,
        const {
            MapConfig::new(
                SETTINGS_FLASH_OFFSET
                    ..SETTINGS_FLASH_OFFSET + (SETTINGS_SECTORS * SETTINGS_SECTOR_BYTES) as u32,
            )
        },
    )
}

/// The record a boot from `image` (the settings sectors) loads, if any.
pub fn load_settings_record(image: Vec<u8>) -> Option<Vec<u8>> {
    let mut store = settings_store(SettingsFlash::from_image(SETTINGS_FLASH_OFFSET, image));
    let mut record = vec![0u8; laser_app::settings::MAX_RECORD_LEN];
    let n = embassy_futures::block_on(store.load(&mut record));
    record.truncate(n);
    (n > 0).then_some(record)
}

/// How to run a simulation.
#[derive(Debug, Clone)]
pub struct SimOptions {
    /// The command lines to type (and waits).
    pub script: Vec<Step>,
    /// Type what the user types on stdin instead of `script` (real time,
    /// until end of input).
    pub interactive: bool,
    /// Pace with the wall clock instead of jumping over idle time.
    pub realtime: bool,
    /// Keep running after the script until the sequencer is idle.
    pub until_idle: bool,
    /// Injected servo-bus faults.
    pub faults: BusFaults,
    /// Servos move this many times slower than commanded (1 = nominal).
    pub slow_factor: f64,
    /// Hard limit on simulated time, ms.
    pub max_time_ms: u64,
    /// Print the terminal transcript on stdout as it happens.
    pub echo: bool,
    /// Period of the spot sampler, µs.
    pub sample_period_us: u64,
    /// Saved settings record to boot with (saved through the store into
    /// erased flash before the boot).
    pub saved_settings: Option<Vec<u8>>,
    /// The settings sectors to boot from, as an earlier run left them
    /// ([`SimReport::settings_flash`]); overrides `saved_settings`.
    pub settings_flash: Option<Vec<u8>>,
    /// Cut the power of the settings flash at this program/erase step
    /// (counted from boot); the flash then refuses every access.
    pub settings_flash_cut: Option<PowerCut>,
    /// The true gimbal: bus ids, geometry, servo mounting and board pose
    /// (set a pose or zero error to model a real, imperfect build).
    pub physical: PhysicalGimbal,
    /// Galvo loop compute time charged per DAC sample, ns (0: the loop
    /// is instant; above the sample period it underruns).
    pub galvo_cost_ns_per_sample: u64,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            script: Vec::new(),
            interactive: false,
            realtime: false,
            until_idle: false,
            faults: BusFaults::default(),
            slow_factor: 1.0,
            max_time_ms: 600_000,
            echo: false,
            sample_period_us: 2_000,
            saved_settings: None,
            settings_flash: None,
            settings_flash_cut: None,
            physical: PhysicalGimbal::default(),
            galvo_cost_ns_per_sample: 0,
        }
    }
}

/// What a simulation produced.
#[derive(Debug, Clone)]
pub struct SimReport {
    /// Everything the terminal sent and received.
    pub transcript: Transcript,
    /// Spot, dwells, laser switching, servo-bus frames.
    pub recording: Recording,
    /// Why the run ended.
    pub end: RunEnd,
    /// Simulated time at the end, µs.
    pub end_time_us: u64,
    /// The sequencer was idle (or holding a goto) at the end.
    pub idle_at_end: bool,
    /// The settings record a reboot would load from the flash as the run
    /// left it, if any.
    pub saved_settings: Option<Vec<u8>>,
    /// The settings sectors at the end (boot the next run from them).
    pub settings_flash: Vec<u8>,
    /// What the settings flash did during the run.
    pub settings_flash_stats: FlashStats,
    /// Every galvo DAC sample.
    pub dac: DacRecording,
    /// Galvo underruns.
    pub galvo_underruns: u32,
    /// CPU-time accounting of every task's steps (polls).
    pub task_steps: Vec<executor::TaskSteps>,
}

impl SimReport {
    /// Whether `--until-idle` should exit 0: script done, idle, and no
    /// `error:` reply unless errors are allowed.
    pub fn succeeded(&self, allow_errors: bool) -> bool {
        self.end != RunEnd::Livelock
            && self.transcript.script_done
            && self.idle_at_end
            && (allow_errors || self.transcript.error_replies == 0)
    }
}

/// The gimbal laser output: the gated pin (which records the effective
/// laser), plus every sequencer event with its time and the servos' true
/// state at each switch and event (for the safety checker).
struct RecordingLaser {
    /// The gated pin that records the effective gimbal laser.
    pin: GatedLaserPin,
    recording: Rc<RefCell<Recording>>,
    bus: Rc<RefCell<SimServoBus>>,
    gimbal: PhysicalGimbal,
}

impl RecordingLaser {
    fn record_servos(&self, rec: &mut Recording, t_us: u64) {
        let laser = rec.laser_at(t_us);
        rec.servos
            .push(servo_sample(&self.bus.borrow(), self.gimbal, t_us, laser));
    }
}

impl LaserSwitch for RecordingLaser {
    fn set(&mut self, on: bool) {
        self.pin.set(on);
        crate::executor::simulator_work(|| {
            let t = crate::clock::now_us();
            let mut rec = self.recording.borrow_mut();
            self.record_servos(&mut rec, t);
        });
    }

    fn note(&mut self, event: LaserEvent<'_>) {
        crate::executor::simulator_work(|| self.record_event(event));
    }
}

impl RecordingLaser {
    fn record_event(&self, event: LaserEvent<'_>) {
        let t_us = crate::clock::now_us();
        let event = match event {
            LaserEvent::Stopped { why } => SequencerEvent::Stopped {
                why: why.to_owned(),
            },
            LaserEvent::RunStarted => SequencerEvent::RunStarted,
            LaserEvent::GimbalMoveSent => SequencerEvent::GimbalMoveSent,
            LaserEvent::GimbalArrived => SequencerEvent::GimbalArrived,
        };
        let mut rec = self.recording.borrow_mut();
        let laser_switches_before = rec.laser_events.len();
        rec.events.push(EventRecord {
            t_us,
            event,
            laser_switches_before,
        });
        self.record_servos(&mut rec, t_us);
    }
}

/// The gimbal servos' true angles and targets at `t_us`.
fn servo_sample(bus: &SimServoBus, gimbal: PhysicalGimbal, t_us: u64, laser: bool) -> ServoSample {
    let state = |id| {
        bus.servo(id).map(|s| ServoState {
            angle_deg: s.angle_deg(t_us),
            target_deg: f64::from(s.target_tenths()) / 10.0,
        })
    };
    ServoSample {
        t_us,
        yaw: state(gimbal.yaw_id),
        pitch: state(gimbal.pitch_id),
        laser,
    }
}

fn is_idle(status: &StatusBoard) -> bool {
    let s = status.snapshot();
    match s.activity {
        Activity::Idle => true,
        Activity::Goto => s.phase == Some(Phase::Holding),
        Activity::Pattern(_) => false,
    }
}

/// Runs one simulation to its end. Independent runs may execute on
/// different threads at the same time.
pub fn run(options: SimOptions) -> SimReport {
    let link: &'static CommandLink = Box::leak(Box::new(CommandLink::new()));
    let servo_link: &'static ServoLink = Box::leak(Box::new(ServoLink::new()));
    let galvo_link: &'static GalvoLink = Box::leak(Box::new(GalvoLink::new()));
    let dac_recording = Rc::new(RefCell::new(DacRecording::default()));
    let gate = recorded_gate(&dac_recording);
    let status: &'static StatusBoard = Box::leak(Box::new(StatusBoard::new()));
    let host = Rc::new(UsbHost::new(options.echo));
    let recording = Rc::new(RefCell::new(Recording::default()));
    let flash = boot_settings_flash(&options);
    let gimbal = options.physical;
    let bus = Rc::new(RefCell::new(SimServoBus::new(
        &[gimbal.yaw_id, gimbal.pitch_id],
        options.slow_factor,
    )));
    let port = Rc::new(SimServoPort::new(
        bus.clone(),
        recording.clone(),
        options.faults.clone(),
        0x5eed,
    ));

    let end = {
        let (host, recording, flash, bus, script) = (
            host.clone(),
            recording.clone(),
            flash.clone(),
            bus.clone(),
            options.script.clone(),
        );
        let interactive = options.interactive;
        let until_idle = options.until_idle;
        let galvo_dac = dac_recording.clone();
        let stop_host = host.clone();
        executor::run(
            options.realtime,
            options.max_time_ms * 1000,
            move |spawner| {
                let console_host = host.clone();
                executor::spawn_task(&spawner, "console", TaskKind::Firmware, async move {
                    let mut rx = &console_host.to_device;
                    let mut tx = &console_host.from_device;
                    laser_app::usb::run_console(&mut rx, &mut tx, link).await;
                });
                if interactive {
                    let (send, lines) = std::sync::mpsc::channel();
                    std::thread::spawn(move || {
                        for line in std::io::stdin().lines().map_while(Result::ok) {
                            if send.send(line).is_err() {
                                break;
                            }
                        }
                    });
                    executor::spawn_task(
                        &spawner,
                        "host (interactive)",
                        TaskKind::Simulator,
                        interactive_task(lines, host.clone()),
                    );
                } else {
                    executor::spawn_task(
                        &spawner,
                        "host (script)",
                        TaskKind::Simulator,
                        script_task(script, host.clone(), link),
                    );
                }
                executor::spawn_task(
                    &spawner,
                    "host (terminal)",
                    TaskKind::Simulator,
                    terminal_task(host.clone()),
                );
                let servo_port = port.clone();
                executor::spawn_task(&spawner, "servo", TaskKind::Firmware, async move {
                    ServoBus::new(
                        PortHandle(servo_port.clone()),
                        PortHandle(servo_port),
                        ServoBusConfig::default(),
                    )
                    .run(servo_link)
                    .await;
                });
                let spot_bus = bus.clone();
                let laser = RecordingLaser {
                    pin: GatedLaserPin::new(
                        recording.clone(),
                        Box::new(move |t_us| gimbal_spot_cm(&spot_bus, gimbal, t_us)),
                    ),
                    recording: recording.clone(),
                    bus: bus.clone(),
                    gimbal,
                };
                let store = settings_store(flash.clone());
                executor::spawn_task(&spawner, "sequencer", TaskKind::Firmware, async move {
                    let mut sequencer =
                        Sequencer::new(link, servo_link, galvo_link, status, laser, gate, store)
                            .await;
                    sequencer.run().await;
                });
                let (dac_recording, cost) = (galvo_dac, options.galvo_cost_ns_per_sample);
                executor::spawn_task(&spawner, "galvo", TaskKind::Firmware, async move {
                    let config = GalvoConfig::default();
                    let mut dac = SimDac::new(
                        GALVO_HALF_LEN,
                        (config.sample_period_s * 1e9) as u64,
                        cost,
                        dac_recording,
                    );
                    match GalvoLoop::new(config) {
                        Ok(mut galvo) => galvo.run(&mut dac, galvo_link, gate).await,
                        Err(e) => log::error!("galvo loop not started: {e}"),
                    }
                });
                executor::spawn_task(
                    &spawner,
                    "spot sampler",
                    TaskKind::Simulator,
                    spot_sampler(
                        bus.clone(),
                        recording.clone(),
                        status,
                        gimbal,
                        options.sample_period_us,
                    ),
                );
            },
            move || {
                let done = stop_host.transcript.borrow().script_done;
                done && (!until_idle || is_idle(status))
            },
        )
    };
    let transcript = host.transcript.borrow().clone();
    let end_time_us = crate::clock::now_us();
    {
        // The trace ends with the laser's final state at the end time.
        let mut rec = recording.borrow_mut();
        if rec.spot.last().is_none_or(|s| s.t_us < end_time_us)
            && let Some((x_cm, y_cm)) = gimbal_spot_cm(&bus, gimbal, end_time_us)
        {
            let laser = crate::laser::gimbal_lit();
            rec.spot.push(SpotSample {
                t_us: end_time_us,
                x_cm,
                y_cm,
                laser,
            });
        }
    }
    let recording = recording.borrow().clone();
    let settings_flash = flash.image();
    let settings_flash_stats = flash.stats();
    let saved_settings = load_settings_record(settings_flash.clone());
    let dac = dac_recording.borrow().clone();
    SimReport {
        transcript,
        recording,
        end,
        end_time_us,
        idle_at_end: is_idle(status),
        saved_settings,
        settings_flash,
        settings_flash_stats,
        dac,
        galvo_underruns: galvo_link.underruns.load(Ordering::Relaxed),
        task_steps: executor::task_steps(),
    }
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
                log::error!("could not seed the settings flash: {e}");
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

/// Where the gimbal spot is at `t_us` (from the simulated servos' true
/// angles through the exact forward kinematics), board cm.
fn gimbal_spot_cm(
    bus: &Rc<RefCell<SimServoBus>>,
    gimbal: PhysicalGimbal,
    t_us: u64,
) -> Option<(f64, f64)> {
    let bus = bus.borrow();
    let yaw_deg = bus.angle_deg(gimbal.yaw_id, t_us).unwrap_or(0.0);
    let pitch_deg = bus.angle_deg(gimbal.pitch_id, t_us).unwrap_or(0.0);
    gimbal.spot_cm(yaw_deg, pitch_deg)
}

/// Samples the spot from the simulated servos' true angles, and records
/// where it was at the end of each dwell.
async fn spot_sampler(
    bus: Rc<RefCell<SimServoBus>>,
    recording: Rc<RefCell<Recording>>,
    status: &'static StatusBoard,
    gimbal: PhysicalGimbal,
    period_us: u64,
) {
    let mut open_dwell: Option<(DwellKey, usize)> = None;
    loop {
        let t_us = crate::clock::now_us();
        let spot = gimbal_spot_cm(&bus, gimbal, t_us);
        {
            let mut rec = recording.borrow_mut();
            let laser = rec.laser_at(t_us);
            rec.servos
                .push(servo_sample(&bus.borrow(), gimbal, t_us, laser));
            if let Some((x_cm, y_cm)) = spot {
                rec.spot.push(SpotSample {
                    t_us,
                    x_cm,
                    y_cm,
                    laser,
                });
            }
            let s = status.snapshot();
            let dwelling = matches!(s.phase, Some(Phase::Dwelling | Phase::Holding));
            let key = DwellKey {
                index: s.point_index,
                pass: s.pass,
                target: s
                    .target
                    .map(|(t, _)| (t.point.x_cm.to_bits(), t.point.y_cm.to_bits())),
            };
            match (dwelling, s.target, spot) {
                (true, Some((target, _)), Some(spot_cm)) => {
                    // The dwell record keeps the last spot seen during the dwell
                    // (the servos settle onto their quantised target).
                    match open_dwell {
                        Some((open_key, i)) if open_key == key => {
                            if let Some(record) = rec.dwells.get_mut(i) {
                                record.spot_cm = spot_cm;
                                record.laser &= laser;
                            }
                        }
                        _ => {
                            rec.dwells.push(DwellRecord {
                                t_us,
                                target_cm: (target.point.x_cm, target.point.y_cm),
                                grid: target.grid,
                                spot_cm,
                                laser,
                            });
                            open_dwell = Some((key, rec.dwells.len() - 1));
                        }
                    }
                }
                _ => open_dwell = None,
            }
        }
        Timer::after_micros(period_us).await;
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct DwellKey {
    index: Option<usize>,
    pass: u32,
    target: Option<(u64, u64)>,
}
