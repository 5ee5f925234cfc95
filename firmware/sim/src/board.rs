//! The simulated board: what it provides to `laser-app`'s one wiring
//! function ([`laser_app::app::wire`]) and how it runs the task bodies
//! (as simulated tasks on the virtual-time executor). The target's board
//! is `firmware/src/board.rs`; the two differ only in these parts.
//!
//! | part          | here                                              |
//! |---------------|---------------------------------------------------|
//! | console       | the simulated terminal's byte pipes ([`UsbHost`]) |
//! | servo UART    | the simulated FashionStar bus ([`SimServoPort`])  |
//! | laser pin     | the recording gated pin ([`RecordingLaser`])      |
//! | settings      | sectors 10 and 11 of the simulated flash          |
//! | galvo DAC     | the simulated double-buffered DAC ([`SimDac`]), or none |
//! | stepper STEP/DIR/ENABLE | the driver models ([`SimStepperDrive`]), or none |
//! | LEDs, button, watchdog | recorded models ([`crate::panel`])       |
//! | interlock, key, emission indicator | script-set inputs, recorded indicator ([`crate::controls`]), or none |
//! | PELCO port (RS-485 UART) | a PTY ([`crate::pelco_port`], `--pelco-pty`), or none |

use std::cell::Cell;
use std::convert::Infallible;
use std::rc::Rc;

use embassy_executor::Spawner;
use laser_app::app::{
    Board, Console, ConsoleTask, GalvoTask, HostPresence, IndicatorTask, LaserControlsTask, Parts,
    PelcoTask, SequencerTask, ServoBusTask, Spawn, StopButtonTask, WatchdogTask,
};
use laser_app::settings::store::FlashSettingsStore;
use laser_app::stepper::{StepPulseTask, StepperTask};

use crate::controls::SimLaserControls;
use crate::dac::SimDac;
use crate::executor::{TaskKind, spawn_task};
use crate::panel::{SimLeds, SimStopButton, SimWatchdog};
use crate::pelco_port::{PelcoRx, PelcoTx};
use crate::servo_port::{PortHandle, SimServoPort};
use crate::settings_flash::SettingsFlash;
use crate::spot::RecordingLaser;
use crate::stepper::SimStepperDrive;
use crate::usb_host::UsbHost;

/// The simulated board's parts.
pub struct SimBoard {
    /// The terminal's side of the console.
    pub host: Rc<UsbHost>,
    /// The servo bus.
    pub servo_port: Rc<SimServoPort>,
    /// The gimbal laser.
    pub laser: RecordingLaser,
    /// The settings store.
    pub settings: FlashSettingsStore<SettingsFlash>,
    /// The galvo DAC, if the board has one.
    pub galvo_dac: Option<SimDac>,
    /// The stepper outputs, if the board has them.
    pub stepper: Option<SimStepperDrive>,
    /// The status LEDs.
    pub leds: SimLeds,
    /// The stop button.
    pub stop_button: SimStopButton,
    /// The watchdog.
    pub watchdog: SimWatchdog,
    /// The laser controls, if the board has them.
    pub laser_controls: Option<SimLaserControls>,
    /// The PELCO port, if the run has one (`--pelco-pty`).
    pub pelco: Option<(PelcoRx, PelcoTx)>,
}

impl Board for SimBoard {
    type Console = SimConsole;
    type ServoRx = PortHandle;
    type ServoTx = PortHandle;
    type Laser = RecordingLaser;
    type Settings = FlashSettingsStore<SettingsFlash>;
    type GalvoDac = SimDac;
    type Stepper = SimStepperDrive;
    type Indicators = SimLeds;
    type StopButton = SimStopButton;
    type Watchdog = SimWatchdog;
    type LaserControls = SimLaserControls;
    type PelcoRx = PelcoRx;
    type PelcoTx = PelcoTx;

    fn into_parts(self) -> Parts<Self> {
        Parts {
            console: SimConsole {
                rx: HostRx(self.host.clone()),
                tx: HostTx(self.host),
                connection: Rc::default(),
            },
            servo_rx: PortHandle(self.servo_port.clone()),
            servo_tx: PortHandle(self.servo_port),
            laser: self.laser,
            settings: self.settings,
            galvo_dac: self.galvo_dac,
            stepper: self.stepper,
            indicators: self.leds,
            stop_button: self.stop_button,
            watchdog: self.watchdog,
            laser_controls: self.laser_controls,
            pelco: self.pelco,
        }
    }
}

/// The console port: the simulated terminal is connected at boot; a
/// script's `@close` / `@open` (or a PTY host closing and opening the
/// port) end its connection and begin the next.
pub struct SimConsole {
    rx: HostRx,
    tx: HostTx,
    /// The connection last returned (`None`: none yet).
    connection: Rc<Cell<Option<u32>>>,
}

impl Console for SimConsole {
    type Rx = HostRx;
    type Tx = HostTx;
    type Presence = SimPresence;

    async fn connected(&mut self) -> (&mut HostRx, &mut HostTx) {
        let host = &self.rx.0;
        if let Some(last) = self.connection.get() {
            host.port_closed(last).await;
        }
        self.connection.set(Some(host.port_opened().await));
        (&mut self.rx, &mut self.tx)
    }

    fn presence(&self) -> SimPresence {
        SimPresence {
            host: self.rx.0.clone(),
            connection: self.connection.clone(),
        }
    }
}

/// The simulated host's presence: it hangs up when its port closes.
pub struct SimPresence {
    host: Rc<UsbHost>,
    /// The connection the console serves.
    connection: Rc<Cell<Option<u32>>>,
}

impl HostPresence for SimPresence {
    async fn hung_up(&mut self) {
        if let Some(connection) = self.connection.get() {
            self.host.port_closed(connection).await;
        }
    }
}

/// Host → device bytes (the CDC-ACM OUT endpoint).
pub struct HostRx(Rc<UsbHost>);

/// Device → host bytes (the CDC-ACM IN endpoint).
pub struct HostTx(Rc<UsbHost>);

impl embedded_io_async::ErrorType for HostRx {
    type Error = Infallible;
}

impl embedded_io_async::Read for HostRx {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        Ok(self.0.to_device.read(buf).await)
    }
}

impl embedded_io_async::ErrorType for HostTx {
    type Error = Infallible;
}

impl embedded_io_async::Write for HostTx {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        Ok(self.0.from_device.write(buf).await)
    }

    async fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

/// Starts the simulated host's tasks.
type HostStart = Box<dyn FnOnce(&Spawner)>;

/// Runs the task bodies as simulated firmware tasks.
pub struct SimSpawner {
    spawner: Spawner,
    /// Starts the simulated host (its tasks run right after the console
    /// they type into).
    host: Option<HostStart>,
}

impl SimSpawner {
    /// Spawns on `spawner`; `host` starts the terminal's tasks once the
    /// console runs.
    pub fn new(spawner: Spawner, host: impl FnOnce(&Spawner) + 'static) -> Self {
        Self {
            spawner,
            host: Some(Box::new(host)),
        }
    }

    fn firmware(&self, name: &'static str, task: impl Future + 'static) {
        spawn_task(&self.spawner, name, TaskKind::Firmware, task);
    }
}

impl Spawn<SimBoard> for SimSpawner {
    fn console(&mut self, task: ConsoleTask<SimConsole>) {
        self.firmware("console", task.run());
        if let Some(host) = self.host.take() {
            host(&self.spawner);
        }
    }

    fn servo_bus(&mut self, task: ServoBusTask<PortHandle, PortHandle>) {
        self.firmware("servo", task.run());
    }

    fn sequencer(
        &mut self,
        task: SequencerTask<RecordingLaser, FlashSettingsStore<SettingsFlash>>,
    ) {
        self.firmware("sequencer", task.run());
    }

    fn galvo(&mut self, task: GalvoTask<SimDac>) {
        self.firmware("galvo", task.run());
    }

    fn step_pulses(&mut self, task: StepPulseTask<SimStepperDrive>) {
        self.firmware("step pulses", task.run());
    }

    fn stepper(&mut self, task: StepperTask) {
        self.firmware("stepper", task.run());
    }

    fn indicators(&mut self, task: IndicatorTask<SimLeds>) {
        self.firmware("indicators", task.run());
    }

    fn stop_button(&mut self, task: StopButtonTask<SimStopButton>) {
        self.firmware("stop button", task.run());
    }

    fn watchdog(&mut self, task: WatchdogTask<SimWatchdog>) {
        self.firmware("watchdog", task.run());
    }

    fn laser_controls(&mut self, task: LaserControlsTask<SimLaserControls>) {
        self.firmware("laser controls", task.run());
    }

    fn pelco(&mut self, task: PelcoTask<PelcoRx, PelcoTx>) {
        self.firmware("pelco", task.run());
    }
}

#[cfg(test)]
mod tests;
