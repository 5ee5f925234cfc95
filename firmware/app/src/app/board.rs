//! What a board provides to the application: the traits a board's parts
//! implement and the [`Board`] that hands them over.
//!
//! The target (`firmware/src/board.rs`, STM32F4DISCOVERY) and the host
//! simulator (`laser-sim`'s `board.rs`) are the two boards. They differ only
//! here: every task body that runs on them is the same code
//! ([`super::tasks`]), wired once ([`super::wire`]).

use embedded_io_async::{Read, Write};

use crate::galvo::{DacSample, DacStream, Half, Underrun};
use crate::laser_controls::ControlInputs;
use crate::pelco::PelcoLine;
use crate::sequencer::{LaserSwitch, SettingsStore};
use crate::stepper::{DriverSignals, StepperDrive};

/// The command-line port: a host that may connect and disconnect (USB
/// CDC-ACM on the target, the simulated terminal's byte pipes on the host).
#[allow(async_fn_in_trait)]
pub trait Console {
    /// Bytes from the host.
    type Rx: Read;
    /// Bytes to the host.
    type Tx: Write;

    /// What tells that the host hung up.
    type Presence: HostPresence;

    /// Waits until a host is connected, then lends both directions of the
    /// port until the console ends (the host disconnected or the input
    /// ended); the next call waits for the next connection.
    async fn connected(&mut self) -> (&mut Self::Rx, &mut Self::Tx);

    /// What tells when the host of the connection [`Self::connected`]
    /// returned last hangs up (closes the port: DTR drops on USB CDC-ACM).
    fn presence(&self) -> Self::Presence;
}

/// A host's presence on the console port.
#[allow(async_fn_in_trait)]
pub trait HostPresence {
    /// Waits until the host of the current connection hangs up (at once
    /// when none is connected); the console then starts a new session
    /// with the next host ([`crate::usb::run_console`]).
    async fn hung_up(&mut self);
}

/// The presence of a port that cannot tell when its host hangs up (a
/// UART without modem lines): a session lasts as long as the port works.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoHangUp;

impl HostPresence for NoHangUp {
    async fn hung_up(&mut self) {
        core::future::pending::<()>().await
    }
}

/// What the status LEDs show.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Leds {
    /// Heartbeat: a 100 ms blink once a second while the indicator task
    /// runs.
    pub heartbeat: bool,
    /// The sequencer has the laser on.
    pub laser: bool,
    /// A servo is faulty.
    pub fault: bool,
}

/// The status LEDs (GPIOs on the target, a recorded timeline in the
/// simulator).
pub trait Indicators {
    /// Shows `leds` until the next call.
    fn show(&mut self, leds: Leds);
}

/// The stop button: stop the run and turn the laser off.
#[allow(async_fn_in_trait)]
pub trait StopButton {
    /// Waits for the next press. A board with a bouncing switch debounces
    /// here (presses during the bounce are not presses).
    async fn pressed(&mut self);
}

/// The laser controls of a Class 3B/4 product (`docs/laser-safety.md`):
/// the remote interlock and key switch inputs and the emission indicator
/// output. The laser-controls task debounces the inputs.
#[allow(async_fn_in_trait)]
pub trait LaserControls {
    /// The raw input levels now. Wiring faults must read as open / off
    /// (the target's inputs are pulled up and closed to ground).
    fn read(&mut self) -> ControlInputs;
    /// Waits until an input may have changed (an edge on either; early
    /// returns are harmless). The task also polls every
    /// [`CONTROLS_POLL`](super::CONTROLS_POLL).
    async fn changed(&mut self);
    /// Switches the emission indicator (LED and/or buzzer).
    fn set_indicator(&mut self, on: bool);
}

/// The laser controls of a board that has none (the simulator unless
/// asked for them): no value of this type exists, so
/// [`Parts::laser_controls`] is `None`, no controls task runs and the
/// master gate stays permitted.
#[derive(Debug)]
pub enum NoLaserControls {}

impl LaserControls for NoLaserControls {
    fn read(&mut self) -> ControlInputs {
        match *self {}
    }

    async fn changed(&mut self) {
        match *self {}
    }

    fn set_indicator(&mut self, _on: bool) {
        match *self {}
    }
}

/// A watchdog that resets the MCU when it is not fed within
/// [`WATCHDOG_TIMEOUT_US`](super::WATCHDOG_TIMEOUT_US).
pub trait Watchdog {
    /// Starts the countdown (it cannot be stopped again).
    fn start(&mut self);
    /// Restarts the countdown.
    fn feed(&mut self);
}

/// The galvo DAC of a board that has none: no value of this type exists,
/// so [`Parts::galvo_dac`] is always `None` and no galvo loop runs
/// (`target galvo` is refused).
#[derive(Debug)]
pub enum NoGalvoDac {}

impl DacStream for NoGalvoDac {
    fn half_len(&self) -> usize {
        match *self {}
    }

    fn set_sample_period(&mut self, _period_s: f64) {
        match *self {}
    }

    fn holds(&self, _sample: DacSample) -> bool {
        match *self {}
    }

    async fn write_half(&mut self, _half: Half<'_>) -> Result<(), Underrun> {
        match *self {}
    }

    async fn repeat_half(&mut self) {
        match *self {}
    }
}

/// The stepper outputs of a board that has none: no value of this type
/// exists, so [`Parts::stepper`] is always `None` and no stepper task runs
/// (`target stepper` is refused).
#[derive(Debug)]
pub enum NoStepper {}

impl crate::stepper::StepPulseTask<NoStepper> {
    /// A board without stepper outputs never gets a step timer task:
    /// its spawner's `step_pulses` hook is this.
    pub fn unreachable(self) -> ! {
        match self.drive {}
    }
}

impl StepperDrive for NoStepper {
    fn set_enabled(&mut self, _enabled: bool) {
        match *self {}
    }

    fn set_signals(&mut self, _signals: DriverSignals) {
        match *self {}
    }

    fn step(&mut self, _step: [bool; 2], _negative: [bool; 2]) {
        match *self {}
    }

    async fn wait_ticks(&mut self, _ticks: u32) {
        match *self {}
    }

    fn restart(&mut self) {
        match *self {}
    }

    fn limits(&mut self) -> [bool; 2] {
        match *self {}
    }
}

/// The PELCO port of a board that has none: no value of this type exists,
/// so [`Parts::pelco`] is always `None` and no PELCO task runs (`pelco
/// status` says so).
#[derive(Debug)]
pub enum NoPelcoPort {}

impl embedded_io_async::ErrorType for NoPelcoPort {
    type Error = core::convert::Infallible;
}

impl Read for NoPelcoPort {
    async fn read(&mut self, _buf: &mut [u8]) -> Result<usize, Self::Error> {
        match *self {}
    }
}

impl Write for NoPelcoPort {
    async fn write(&mut self, _buf: &[u8]) -> Result<usize, Self::Error> {
        match *self {}
    }

    async fn flush(&mut self) -> Result<(), Self::Error> {
        match *self {}
    }
}

impl PelcoLine for NoPelcoPort {
    fn set_baud(&mut self, _baud: u32) {
        match *self {}
    }
}

impl crate::pelco::PelcoTask<NoPelcoPort, NoPelcoPort> {
    /// A board without a PELCO port never gets this task: its spawner's
    /// `pelco` hook is this.
    pub fn unreachable(self) -> ! {
        match self.rx {}
    }
}

/// A board: the types of its parts, and the parts themselves
/// ([`Board::into_parts`]), configured and with the laser off.
pub trait Board {
    /// The command-line port.
    type Console: Console;
    /// Bytes from the servo bus (UART receive).
    type ServoRx: Read;
    /// Bytes to the servo bus (UART transmit).
    type ServoTx: Write;
    /// The gimbal's laser-enable output (ANDed with the master laser gate).
    type Laser: LaserSwitch;
    /// Where settings are saved.
    type Settings: SettingsStore;
    /// The galvo DAC stream ([`NoGalvoDac`] on a board without one).
    type GalvoDac: DacStream;
    /// The stepper pan/tilt's STEP/DIR/ENABLE outputs and step timer
    /// ([`NoStepper`] on a board without one).
    type Stepper: StepperDrive;
    /// The status LEDs.
    type Indicators: Indicators;
    /// The stop button.
    type StopButton: StopButton;
    /// The watchdog.
    type Watchdog: Watchdog;
    /// The interlock, key switch and emission indicator
    /// ([`NoLaserControls`] on a board without them).
    type LaserControls: LaserControls;
    /// Bytes from the PELCO bus (RS-485 receive; [`NoPelcoPort`] on a
    /// board without the port).
    type PelcoRx: Read;
    /// Bytes to the PELCO bus (the board drives the RS-485 driver enable
    /// around them: high from the first byte written until `flush` has
    /// seen the last one leave).
    type PelcoTx: Write + PelcoLine;

    /// Hands the parts over to the application.
    fn into_parts(self) -> Parts<Self>
    where
        Self: Sized;
}

/// Everything a [`Board`] provides.
pub struct Parts<B: Board + ?Sized> {
    /// The command-line port.
    pub console: B::Console,
    /// Servo bus, receive half.
    pub servo_rx: B::ServoRx,
    /// Servo bus, transmit half.
    pub servo_tx: B::ServoTx,
    /// The gimbal laser output (off).
    pub laser: B::Laser,
    /// The settings store.
    pub settings: B::Settings,
    /// The galvo DAC, when the board has one (else no galvo loop runs).
    pub galvo_dac: Option<B::GalvoDac>,
    /// The stepper outputs, when the board has them (else no stepper task
    /// runs).
    pub stepper: Option<B::Stepper>,
    /// The status LEDs.
    pub indicators: B::Indicators,
    /// The stop button.
    pub stop_button: B::StopButton,
    /// The watchdog (not started yet).
    pub watchdog: B::Watchdog,
    /// The laser controls (indicator off), when the board has them: then
    /// no laser emits until they are armed.
    pub laser_controls: Option<B::LaserControls>,
    /// The PELCO port's receive and transmit halves, when the board has
    /// one (else no PELCO task runs).
    pub pelco: Option<(B::PelcoRx, B::PelcoTx)>,
}
