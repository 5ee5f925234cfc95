//! Thin `#[embassy_executor::task]` wrappers: embassy tasks cannot be
//! generic, so each runs one of `laser-app`'s task bodies for this board's
//! part types, and [`TaskSpawner`] is the board's spawn hook for
//! `laser_app::app::wire`. The USB device stack is the board's own task.
//! Every task runs in thread mode except the galvo loop, which runs on
//! the galvo executor (an interrupt, `main.rs`) so that nothing in thread
//! mode can delay a refill, and the stepper's step timer, on its own
//! interrupt executor above it (below).

use embassy_executor::{InterruptExecutor, SendSpawner, Spawner};
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::usart::{BufferedUartRx, BufferedUartTx};
use laser_app::app::{
    ConsoleTask, GalvoTask, IndicatorTask, LaserControlsTask, PelcoTask, SequencerTask,
    ServoBusTask, Spawn, StopButtonTask, WatchdogTask,
};
use laser_app::galvo::GalvoMemory;

use static_cell::StaticCell;

use crate::board::Stm32Board;
use crate::galvo_dac::{self, Stm32GalvoDac};
use crate::laser_pwm::LaserPin;
use crate::parts::{
    IndependentDog, LaserControlPins, StatusLeds, TimerStepper, UsbConsole, UserButton,
};
use crate::rs485::Rs485Tx;
use crate::settings_flash::FlashSettings;
use laser_app::stepper::{StepPulseTask, StepperTask};

/// Serves the command line on the CDC-ACM port; restarts on reconnect.
#[embassy_executor::task]
async fn console(task: ConsoleTask<UsbConsole>) -> ! {
    task.run().await
}

/// Owns the servo UART (USART2, interrupt-driven).
#[embassy_executor::task]
async fn servo_bus(task: ServoBusTask<BufferedUartRx<'static>, BufferedUartTx<'static>>) -> ! {
    task.run().await
}

/// Runs the sequencer (commands, patterns, laser).
#[embassy_executor::task]
async fn sequencer(task: SequencerTask<LaserPin, FlashSettings>) -> ! {
    task.run().await
}

/// The galvo loop (on the galvo executor): feeds the DAC stream.
#[embassy_executor::task]
async fn galvo(task: GalvoTask<Stm32GalvoDac>) {
    // The loop's memory in a static (.bss), not in this task's future;
    // written in place (`init_with` would build its 22 KB on this stack,
    // a const initialiser would put 22 KB of .data in flash).
    static MEMORY: StaticCell<GalvoMemory<{ galvo_dac::HALF_LEN }>> = StaticCell::new();
    task.run_in(GalvoMemory::init_in(MEMORY.uninit())).await
}

/// The stepper step timer: executes the prepared segments on PE9–PE13
/// (each event sets DIR and starts TIM1's one-pulse STEP pulses). Runs on
/// [`STEP_EXECUTOR`], above the galvo executor and thread mode.
#[embassy_executor::task]
async fn step_pulses(task: StepPulseTask<TimerStepper>) -> ! {
    task.run().await
}

/// Priority of the step timer's executor: P0, with the short peripheral
/// handlers (a step event is about 1 µs: Bresenham, DIR pins and five
/// TIM1 register writes; the pulse and DIR setup are timed by TIM1, not
/// waited for), above the galvo executor (P1), whose refills (up to
/// ~0.5 ms) would otherwise delay steps by most of a period at
/// 1 600 steps/s.
const STEP_PRIORITY: Priority = Priority::P0;

/// The step timer's executor: an interrupt executor on CAN2_RX1 (a
/// peripheral interrupt this board does not use, pended in software).
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

/// Laser controls PD1–PD3: interlock, key switch, emission indicator (on
/// the galvo executor).
#[embassy_executor::task]
async fn laser_controls(task: LaserControlsTask<LaserControlPins>) -> ! {
    task.run().await
}

/// The PELCO port on USART3 (RS-485): frames from a CCTV keyboard or PTZ
/// software as the product's commands.
#[embassy_executor::task]
async fn pelco(task: PelcoTask<BufferedUartRx<'static>, Rs485Tx>) -> ! {
    task.run().await
}

/// Spawns the task bodies on the embassy executors (each task's pool holds
/// one: the wiring spawns each once).
pub struct TaskSpawner {
    /// The thread-mode executor.
    pub thread: Spawner,
    /// The galvo executor (interrupt priority `board::GALVO_PRIORITY`).
    pub galvo: SendSpawner,
}

impl Spawn<Stm32Board> for TaskSpawner {
    fn console(&mut self, task: ConsoleTask<UsbConsole>) {
        self.thread.spawn(defmt::unwrap!(console(task)));
    }

    fn servo_bus(&mut self, task: ServoBusTask<BufferedUartRx<'static>, BufferedUartTx<'static>>) {
        self.thread.spawn(defmt::unwrap!(servo_bus(task)));
    }

    fn sequencer(&mut self, task: SequencerTask<LaserPin, FlashSettings>) {
        self.thread.spawn(defmt::unwrap!(sequencer(task)));
    }

    fn galvo(&mut self, task: GalvoTask<Stm32GalvoDac>) {
        self.galvo.spawn(defmt::unwrap!(galvo(task)));
    }

    fn step_pulses(&mut self, task: StepPulseTask<TimerStepper>) {
        interrupt::CAN2_RX1.set_priority(STEP_PRIORITY);
        let spawner = STEP_EXECUTOR.start(interrupt::CAN2_RX1);
        spawner.spawn(defmt::unwrap!(step_pulses(task)));
    }

    fn stepper(&mut self, task: StepperTask) {
        self.thread.spawn(defmt::unwrap!(stepper(task)));
    }

    fn indicators(&mut self, task: IndicatorTask<StatusLeds>) {
        self.thread.spawn(defmt::unwrap!(indicators(task)));
    }

    fn stop_button(&mut self, task: StopButtonTask<UserButton>) {
        self.thread.spawn(defmt::unwrap!(stop_button(task)));
    }

    fn watchdog(&mut self, task: WatchdogTask<IndependentDog>) {
        self.thread.spawn(defmt::unwrap!(watchdog(task)));
    }

    fn laser_controls(&mut self, task: LaserControlsTask<LaserControlPins>) {
        // On the galvo executor (interrupt priority): an opening
        // interlock darkens the laser without waiting for a thread-mode
        // task's step to end.
        self.galvo.spawn(defmt::unwrap!(laser_controls(task)));
    }

    fn pelco(&mut self, task: PelcoTask<BufferedUartRx<'static>, Rs485Tx>) {
        self.thread.spawn(defmt::unwrap!(pelco(task)));
    }
}
