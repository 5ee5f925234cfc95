//! Thin `#[embassy_executor::task]` wrappers (embassy tasks cannot be
//! generic): each runs one of laser-app's task bodies for this board's
//! part types; [`TaskSpawner`] is the board's spawn hook for
//! `laser_app::app::wire`.

use embassy_executor::Spawner;
#[cfg(not(feature = "galvo-dac"))]
use laser_app::app::NoGalvoDac;
use laser_app::app::{
    ConsoleTask, GalvoTask, IndicatorTask, LaserControlsTask, NoStepper, PelcoTask, SequencerTask,
    ServoBusTask, Spawn, StopButtonTask, WatchdogTask,
};
use laser_app::stepper::{StepPulseTask, StepperTask};

use crate::board::QemuBoard;
use crate::parts::{CmsdkWatchdog, LaserPin, ReportedLeds, UartButton, UartConsole};
use crate::settings_ram::RamSettings;
use crate::uart::Uart;

#[embassy_executor::task]
async fn console(task: ConsoleTask<UartConsole>) -> ! {
    task.run().await
}

#[embassy_executor::task]
async fn servo_bus(task: ServoBusTask<Uart, Uart>) -> ! {
    task.run().await
}

#[cfg(feature = "laser-controls")]
#[embassy_executor::task]
async fn laser_controls(task: LaserControlsTask<crate::controls::ChannelLaserControls>) -> ! {
    task.run().await
}

#[embassy_executor::task]
async fn pelco(task: PelcoTask<Uart, Uart>) -> ! {
    task.run().await
}

#[embassy_executor::task]
async fn sequencer(task: SequencerTask<LaserPin, RamSettings>) -> ! {
    task.run().await
}

#[cfg(feature = "galvo-dac")]
#[embassy_executor::task]
async fn galvo(task: GalvoTask<crate::galvo_dac::QemuDac>) {
    // The loop's memory in a static, not in this task's future (as on the
    // STM32 board), built at compile time, not on this stack.
    static MEMORY: static_cell::StaticCell<
        laser_app::galvo::GalvoMemory<{ crate::galvo_dac::HALF_LEN }>,
    > = static_cell::StaticCell::new();
    task.run_in(laser_app::galvo::GalvoMemory::init_in(MEMORY.uninit()))
        .await
}

/// The stepper task (planning, segment prep). The board has no stepper
/// outputs, so `wire` never spawns it; it is here so the board's spawn hooks
/// are complete, as on the STM32 board.
#[embassy_executor::task]
async fn stepper(task: StepperTask) {
    task.run().await
}

#[embassy_executor::task]
async fn indicators(task: IndicatorTask<ReportedLeds>) -> ! {
    task.run().await
}

#[embassy_executor::task]
async fn stop_button(task: StopButtonTask<UartButton>) -> ! {
    task.run().await
}

#[embassy_executor::task]
async fn watchdog(task: WatchdogTask<CmsdkWatchdog>) -> ! {
    task.run().await
}

/// Spawns the task bodies (each pool holds one: the wiring spawns each
/// once; a second spawn would be a wiring bug, reported and skipped).
pub struct TaskSpawner(pub Spawner);

fn spawned<S>(
    name: &str,
    token: Result<embassy_executor::SpawnToken<S>, embassy_executor::SpawnError>,
    spawner: &Spawner,
) {
    match token {
        Ok(token) => spawner.spawn(token),
        Err(_) => log::error!("task {name} spawned twice: not started again"),
    }
}

impl Spawn<QemuBoard> for TaskSpawner {
    fn console(&mut self, task: ConsoleTask<UartConsole>) {
        spawned("console", console(task), &self.0);
    }

    fn servo_bus(&mut self, task: ServoBusTask<Uart, Uart>) {
        spawned("servo bus", servo_bus(task), &self.0);
    }

    fn sequencer(&mut self, task: SequencerTask<LaserPin, RamSettings>) {
        spawned("sequencer", sequencer(task), &self.0);
    }

    #[cfg(not(feature = "galvo-dac"))]
    fn galvo(&mut self, task: GalvoTask<NoGalvoDac>) {
        task.unreachable()
    }

    #[cfg(feature = "galvo-dac")]
    fn galvo(&mut self, task: GalvoTask<crate::galvo_dac::QemuDac>) {
        spawned("galvo", galvo(task), &self.0);
    }

    fn step_pulses(&mut self, task: StepPulseTask<NoStepper>) {
        task.unreachable()
    }

    fn stepper(&mut self, task: StepperTask) {
        spawned("stepper", stepper(task), &self.0);
    }

    fn indicators(&mut self, task: IndicatorTask<ReportedLeds>) {
        spawned("indicators", indicators(task), &self.0);
    }

    fn stop_button(&mut self, task: StopButtonTask<UartButton>) {
        spawned("stop button", stop_button(task), &self.0);
    }

    #[cfg(not(feature = "laser-controls"))]
    fn laser_controls(&mut self, task: LaserControlsTask<laser_app::app::NoLaserControls>) {
        task.unreachable()
    }

    #[cfg(feature = "laser-controls")]
    fn laser_controls(&mut self, task: LaserControlsTask<crate::controls::ChannelLaserControls>) {
        spawned("laser controls", laser_controls(task), &self.0);
    }

    fn watchdog(&mut self, task: WatchdogTask<CmsdkWatchdog>) {
        spawned("watchdog", watchdog(task), &self.0);
    }

    fn pelco(&mut self, task: PelcoTask<Uart, Uart>) {
        spawned("pelco", pelco(task), &self.0);
    }
}
