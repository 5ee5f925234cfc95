//! The application, wired once: [`wire`] builds every task body from a
//! [`Board`]'s parts and the shared [`Links`] and hands each to the
//! board's [`Spawn`] hook. The target (`firmware/src/main.rs`) and the
//! simulator (`laser-sim`'s `world`) each construct their board and call
//! it, so the simulator runs the target's task graph.
//!
//! ```text
//!   PELCO port ─▶ PELCO ─┐ (quiet commands)
//! console port ─▶ console ─CommandLink─▶ sequencer ─ServoLink─▶ servo bus ─▶ servo UART
//!                      stop button ─┘     │  │  ├─GalvoLink─▶ galvo loop ─▶ galvo DAC (if any)
//!                                         │  │  └─StepperLink─▶ stepper task ─▶ step timer ─▶ STEP/DIR (if any)
//!                                         │  └─▶ laser pin (every laser behind the LaserGate)
//!                                         └─StatusBoard─▶ indicators (LEDs), watchdog
//! ```
//!
//! See `ARCHITECTURE.md` for what a board provides and how to add one.

mod board;
mod controls;
mod links;
mod tasks;

pub use self::board::{
    Board, Console, HostPresence, Indicators, LaserControls, Leds, NoGalvoDac, NoHangUp,
    NoLaserControls, NoPelcoPort, NoStepper, Parts, StopButton, Watchdog,
};
pub use self::controls::{CONTROLS_POLL, LaserControlsTask};
pub use self::links::Links;
pub use self::tasks::{
    ConsoleTask, GalvoTask, HEARTBEAT_TICKS, INDICATOR_PERIOD, IndicatorTask, SequencerTask,
    ServoBusTask, StopButtonTask, WATCHDOG_CHECK_PERIOD, WATCHDOG_TIMEOUT_US, WatchdogTask,
    leds_at,
};
pub use crate::pelco::{PelcoLine, PelcoTask};

use crate::stepper::{StepPulseTask, StepperConfig, StepperTask};

/// Runs task bodies as tasks. Embassy tasks cannot be generic, so a board
/// implements one hook per task for its own part types: on the target a
/// thin `#[embassy_executor::task]` wrapper around `task.run()`, in the
/// simulator a simulated task.
pub trait Spawn<B: Board> {
    /// The command line.
    fn console(&mut self, task: ConsoleTask<B::Console>);
    /// The servo bus.
    fn servo_bus(&mut self, task: ServoBusTask<B::ServoRx, B::ServoTx>);
    /// The sequencer.
    fn sequencer(&mut self, task: SequencerTask<B::Laser, B::Settings>);
    /// The galvo loop (only called when the board has a galvo DAC; a board
    /// with [`NoGalvoDac`] answers [`GalvoTask::unreachable`]).
    fn galvo(&mut self, task: GalvoTask<B::GalvoDac>);
    /// The step timer, at high priority (only called when the board has
    /// stepper outputs; a board with [`NoStepper`] answers
    /// [`StepPulseTask::unreachable`]).
    fn step_pulses(&mut self, task: StepPulseTask<B::Stepper>);
    /// The stepper task (planning, segment prep), at low priority.
    fn stepper(&mut self, task: StepperTask);
    /// The status LEDs.
    fn indicators(&mut self, task: IndicatorTask<B::Indicators>);
    /// The stop button.
    fn stop_button(&mut self, task: StopButtonTask<B::StopButton>);
    /// The watchdog.
    fn watchdog(&mut self, task: WatchdogTask<B::Watchdog>);
    /// The laser controls (only called when the board has them; a board
    /// with [`NoLaserControls`] answers [`LaserControlsTask::unreachable`]).
    fn laser_controls(&mut self, task: LaserControlsTask<B::LaserControls>);
    /// The PELCO port (only called when the board has one; a board with
    /// [`NoPelcoPort`] answers [`PelcoTask::unreachable`]).
    fn pelco(&mut self, task: PelcoTask<B::PelcoRx, B::PelcoTx>);
}

/// Builds the whole task set from `board` and `links` and spawns it
/// through `spawner`, in dataflow order: console, servo bus, sequencer,
/// galvo loop (when the board has a DAC), step timer and stepper task
/// (when it has stepper outputs), then the LEDs, the stop button, the
/// watchdog, the laser controls (when it has them: the gate is
/// forbidden before anything is spawned) and the PELCO port (when it has
/// one).
pub fn wire<B: Board>(board: B, links: Links, spawner: &mut impl Spawn<B>) {
    let parts = board.into_parts();
    if parts.laser_controls.is_some() {
        // Power-up: no emission until armed, from before any task runs.
        links.gate.forbid();
    }
    spawner.console(ConsoleTask {
        port: parts.console,
        link: links.command,
    });
    spawner.servo_bus(ServoBusTask {
        rx: parts.servo_rx,
        tx: parts.servo_tx,
        link: links.servo,
    });
    spawner.sequencer(SequencerTask {
        laser: parts.laser,
        store: parts.settings,
        links,
    });
    if let Some(dac) = parts.galvo_dac {
        spawner.galvo(GalvoTask {
            dac,
            link: links.galvo,
            gate: links.gate,
        });
    }
    if let Some(drive) = parts.stepper {
        spawner.step_pulses(StepPulseTask {
            drive,
            link: links.stepper,
        });
        spawner.stepper(StepperTask {
            link: links.stepper,
            config: StepperConfig::default(),
        });
    }
    spawner.indicators(IndicatorTask {
        leds: parts.indicators,
        status: links.status,
    });
    spawner.stop_button(StopButtonTask {
        button: parts.stop_button,
        link: links.command,
        stepper: links.stepper,
    });
    spawner.watchdog(WatchdogTask {
        dog: parts.watchdog,
        status: links.status,
        servo: links.servo,
    });
    if let Some(controls) = parts.laser_controls {
        spawner.laser_controls(LaserControlsTask {
            controls,
            link: links.controls,
            gate: links.gate,
            command: links.command,
        });
    }
    if let Some((rx, tx)) = parts.pelco {
        spawner.pelco(PelcoTask {
            rx,
            tx,
            link: links.command,
            status: links.status,
        });
    }
}

#[cfg(test)]
mod tests;
