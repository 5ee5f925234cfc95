//! The task bodies, each built by [`super::wire`] from a board's parts and
//! the shared links, and run by the board's spawner
//! ([`super::Spawn`]): on the target inside a thin
//! `#[embassy_executor::task]` wrapper, in the simulator as a simulated
//! task. Each `run` is the whole task.

use core::sync::atomic::Ordering;

use embassy_futures::select::{Either, select};
use embassy_time::{Duration, Timer};
use embedded_io_async::{Read, Write};

use super::board::{Console, HostPresence, Indicators, Leds, StopButton, Watchdog};
use super::links::Links;
use crate::command::CommandLink;
use crate::galvo::{DacStream, GalvoConfig, GalvoLink, GalvoLoop, GalvoMemory};
use crate::laser_gate::LaserGate;
use crate::log;
use crate::sequencer::{ActuatorLinks, LaserSwitch, Sequencer, SettingsStore};
use crate::servo::task::{ServoBus, ServoBusConfig, ServoLink};
use crate::status::StatusBoard;
use crate::stepper::StepperLink;

/// Period of the status LEDs' update.
pub const INDICATOR_PERIOD: Duration = Duration::from_millis(100);
/// The heartbeat LED is lit for one indicator period in this many.
pub const HEARTBEAT_TICKS: u32 = 10;
/// How often the watchdog task looks for progress (and feeds).
pub const WATCHDOG_CHECK_PERIOD: Duration = Duration::from_millis(1000);
/// The watchdog's timeout every board configures, µs (4 s: a flash-sector
/// erase for `save` stalls the CPU for up to ~2 s).
pub const WATCHDOG_TIMEOUT_US: u32 = 4_000_000;

/// The command line: serves each host connection on the console port.
pub struct ConsoleTask<C> {
    pub(super) port: C,
    pub(super) link: &'static CommandLink,
}

impl<C: Console> ConsoleTask<C> {
    /// Serves the command line, connection after connection: each ends
    /// when its host hangs up (or the port fails), and the next one is a
    /// new session.
    pub async fn run(mut self) -> ! {
        let mut presence = self.port.presence();
        loop {
            let (rx, tx) = self.port.connected().await;
            log::info!("console: host connected");
            let session = crate::usb::run_console(rx, tx, self.link);
            // The hang-up first: nothing more is written to a closed port.
            match select(presence.hung_up(), session).await {
                Either::First(()) => log::info!("console: host hung up"),
                Either::Second(end) => log::info!("console: ended ({:?})", end),
            }
        }
    }
}

/// The servo bus: owns the servo UART.
pub struct ServoBusTask<R, W> {
    pub(super) rx: R,
    pub(super) tx: W,
    pub(super) link: &'static ServoLink,
}

impl<R: Read, W: Write> ServoBusTask<R, W> {
    /// Serves the sequencer's servo requests.
    pub async fn run(self) -> ! {
        ServoBus::new(self.rx, self.tx, ServoBusConfig::default())
            .run(self.link)
            .await
    }
}

/// The sequencer: commands, patterns, laser.
pub struct SequencerTask<L, S> {
    pub(super) laser: L,
    pub(super) store: S,
    pub(super) links: Links,
}

impl<L: LaserSwitch, S: SettingsStore> SequencerTask<L, S> {
    /// Loads the settings, then runs commands and patterns.
    pub async fn run(self) -> ! {
        let Links {
            command,
            servo,
            galvo,
            status,
            gate,
            stepper,
            controls,
        } = self.links;
        let actuators = ActuatorLinks {
            galvo,
            stepper,
            controls,
        };
        let mut sequencer = Sequencer::new(
            command, servo, actuators, status, self.laser, gate, self.store,
        )
        .await;
        sequencer.run().await
    }
}

/// The galvo loop: feeds the board's DAC.
pub struct GalvoTask<D> {
    pub(super) dac: D,
    pub(super) link: &'static GalvoLink,
    pub(super) gate: &'static LaserGate,
}

impl<D: DacStream> GalvoTask<D> {
    /// Runs the loop with the default parameters until the sequencer
    /// sends the user's; ends at once (logged) if those defaults are
    /// refused.
    ///
    /// The loop lives inside this task's future (a few tens of KB): a
    /// board with little RAM uses [`Self::run_in`].
    pub async fn run(self) {
        let mut memory: GalvoMemory = GalvoMemory::new();
        self.run_in(&mut memory).await
    }

    /// [`Self::run`] with the loop and its half buffer in `memory` (a
    /// board's `static`): the future holds only the reference.
    /// Ends at once (logged) when its half buffer is shorter than the
    /// DAC's halves.
    pub async fn run_in<const HALF: usize>(mut self, memory: &mut GalvoMemory<HALF>) {
        if !GalvoLoop::fits(&self.dac, HALF) {
            log::error!(
                "galvo loop not started: the DAC's {}-sample halves exceed its {}-sample buffer",
                self.dac.half_len(),
                HALF
            );
            return;
        }
        let GalvoMemory { galvo, half } = memory;
        let galvo = match GalvoLoop::start_in::<D>(galvo, GalvoConfig::default()) {
            Ok(galvo) => galvo,
            Err(e) => {
                log::error!("galvo loop not started: {}", e);
                return;
            }
        };
        galvo
            .run_with(&mut self.dac, self.link, self.gate, half)
            .await
    }
}

impl GalvoTask<super::board::NoGalvoDac> {
    /// A board without a DAC never gets a galvo task (there is no DAC to
    /// put in one): its spawner's `galvo` hook is this.
    pub fn unreachable(self) -> ! {
        match self.dac {}
    }
}

/// The status LEDs: heartbeat, laser, fault.
pub struct IndicatorTask<I> {
    pub(super) leds: I,
    pub(super) status: &'static StatusBoard,
}

/// What the LEDs show at indicator tick `tick` (one tick per
/// [`INDICATOR_PERIOD`]).
pub fn leds_at(status: &StatusBoard, tick: u32) -> Leds {
    let s = status.snapshot();
    Leds {
        heartbeat: tick.is_multiple_of(HEARTBEAT_TICKS),
        laser: s.laser_on,
        fault: s.faulty_servo.is_some(),
    }
}

impl<I: Indicators> IndicatorTask<I> {
    /// Updates the LEDs every [`INDICATOR_PERIOD`].
    pub async fn run(mut self) -> ! {
        let mut tick: u32 = 0;
        loop {
            self.leds.show(leds_at(self.status, tick));
            tick = tick.wrapping_add(1);
            Timer::after(INDICATOR_PERIOD).await;
        }
    }
}

/// The stop button: stop the run, laser off (as the `stop` command), and
/// the stepper's steps halted at once.
pub struct StopButtonTask<B> {
    pub(super) button: B,
    pub(super) link: &'static CommandLink,
    pub(super) stepper: &'static StepperLink,
}

impl<B: StopButton> StopButtonTask<B> {
    /// Turns each press into a stop request (and a stepper halt).
    pub async fn run(mut self) -> ! {
        loop {
            self.button.pressed().await;
            log::info!("button: stop");
            self.stepper.halt();
            self.link.stop_request.signal(());
        }
    }
}

/// The watchdog: fed only while the sequencer and the servo task both
/// show progress, so a hung task resets the MCU (laser off at reset).
pub struct WatchdogTask<W> {
    pub(super) dog: W,
    pub(super) status: &'static StatusBoard,
    pub(super) servo: &'static ServoLink,
}

impl<W: Watchdog> WatchdogTask<W> {
    /// The progress counters: the sequencer's heartbeat, the servo task's
    /// liveness count.
    fn progress(&self) -> (u32, u32) {
        (
            self.status.snapshot().heartbeat,
            self.servo.alive.load(Ordering::Relaxed),
        )
    }

    /// Starts the watchdog, then feeds it every
    /// [`WATCHDOG_CHECK_PERIOD`] in which both tasks made progress.
    pub async fn run(mut self) -> ! {
        self.dog.start();
        let mut last = self.progress();
        loop {
            Timer::after(WATCHDOG_CHECK_PERIOD).await;
            let now = self.progress();
            if now.0 != last.0 && now.1 != last.1 {
                self.dog.feed();
            } else {
                log::warning!("watchdog: a task shows no progress; not feeding");
            }
            last = now;
        }
    }
}
