//! Thin `#[embassy_executor::task]` wrappers: embassy tasks cannot be
//! generic, so each runs one of `laser-app`'s task bodies for this board's
//! part types, and [`TaskSpawner`] is the board's spawn hook for
//! `laser_app::app::wire`. The USB device stack is the board's own task.

use embassy_executor::{InterruptExecutor, Spawner};
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::mode::Async;
use embassy_stm32::usart::{RingBufferedUartRx, UartTx};
use embassy_usb::UsbDevice;
use laser_app::app::{
    ConsoleTask, GalvoTask, IndicatorTask, NoGalvoDac, SequencerTask, ServoBusTask, Spawn,
    StopButtonTask, WatchdogTask,
};

use crate::board::Stm32Board;
use laser_app::stepper::{StepPulseTask, StepperTask};

use crate::parts::{
    GpioStepper, IndependentDog, LaserPin, StatusLeds, UsbConsole, UsbDriver, UserButton,
};
use crate::settings_flash::FlashSettings;

/// Runs the USB device stack (enumeration, control requests).
#[embassy_executor::task]
pub async fn usb_device(mut device: UsbDevice<'static, UsbDriver>) -> ! {
    device.run().await
}

/// Serves the command line on the CDC-ACM port; restarts on reconnect.
#[embassy_executor::task]
async fn console(task: ConsoleTask<UsbConsole>) -> ! {
    task.run().await
}

/// Owns the servo UART (USART2, DMA both ways).
#[embassy_executor::task]
async fn servo_bus(task: ServoBusTask<RingBufferedUartRx<'static>, UartTx<'static, Async>>) -> ! {
    task.run().await
}

/// Runs the sequencer (commands, patterns, laser).
#[embassy_executor::task]
async fn sequencer(task: SequencerTask<LaserPin, FlashSettings>) -> ! {
    task.run().await
}

/// The stepper step timer: executes the prepared segments on PE9–PE13.
/// Runs on [`STEP_EXECUTOR`], above every thread-mode task.
#[embassy_executor::task]
async fn step_pulses(task: StepPulseTask<GpioStepper>) -> ! {
    task.run().await
}

/// The step timer's executor: an interrupt executor on CAN2_RX1 (a
/// peripheral interrupt this board does not use, pended in software) at
/// priority 2, so the step timer preempts USB, the sequencer and the
/// stepper task's planning.
static STEP_EXECUTOR: InterruptExecutor = InterruptExecutor::new();

#[interrupt]
unsafe fn CAN2_RX1() {
    // SAFETY: the interrupt `STEP_EXECUTOR` was started on (below).
    unsafe { STEP_EXECUTOR.on_interrupt() }
}

/// The stepper task: planning and segment prep for the pan/tilt.
#[embassy_executor::task]
async fn stepper(task: StepperTask) {
    task.run().await
}

/// Status LEDs: heartbeat (green), laser (orange), fault (red).
#[embassy_executor::task]
async fn indicators(task: IndicatorTask<StatusLeds>) -> ! {
    task.run().await
}

/// User button PA0: stop the pattern and turn the laser off.
#[embassy_executor::task]
async fn stop_button(task: StopButtonTask<UserButton>) -> ! {
    task.run().await
}

/// Independent watchdog: fed while the sequencer and the servo task both
/// show progress.
#[embassy_executor::task]
async fn watchdog(task: WatchdogTask<IndependentDog>) -> ! {
    task.run().await
}

/// Spawns the task bodies on the embassy executor (each task's pool holds
/// one: the wiring spawns each once).
pub struct TaskSpawner(pub Spawner);

impl Spawn<Stm32Board> for TaskSpawner {
    fn console(&mut self, task: ConsoleTask<UsbConsole>) {
        self.0.spawn(defmt::unwrap!(console(task)));
    }

    fn servo_bus(
        &mut self,
        task: ServoBusTask<RingBufferedUartRx<'static>, UartTx<'static, Async>>,
    ) {
        self.0.spawn(defmt::unwrap!(servo_bus(task)));
    }

    fn sequencer(&mut self, task: SequencerTask<LaserPin, FlashSettings>) {
        self.0.spawn(defmt::unwrap!(sequencer(task)));
    }

    fn galvo(&mut self, task: GalvoTask<NoGalvoDac>) {
        task.unreachable()
    }

    fn step_pulses(&mut self, task: StepPulseTask<GpioStepper>) {
        interrupt::CAN2_RX1.set_priority(Priority::P2);
        let spawner = STEP_EXECUTOR.start(interrupt::CAN2_RX1);
        spawner.spawn(defmt::unwrap!(step_pulses(task)));
    }

    fn stepper(&mut self, task: StepperTask) {
        self.0.spawn(defmt::unwrap!(stepper(task)));
    }

    fn indicators(&mut self, task: IndicatorTask<StatusLeds>) {
        self.0.spawn(defmt::unwrap!(indicators(task)));
    }

    fn stop_button(&mut self, task: StopButtonTask<UserButton>) {
        self.0.spawn(defmt::unwrap!(stop_button(task)));
    }

    fn watchdog(&mut self, task: WatchdogTask<IndependentDog>) {
        self.0.spawn(defmt::unwrap!(watchdog(task)));
    }
}
