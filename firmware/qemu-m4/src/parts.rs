//! The MPS2 AN386's peripherals as the application's parts: each
//! implements one of laser-app's board traits. The board has no laser pin
//! or LEDs: their state is reported on the log channel, stamped with the
//! board's time, as an oscilloscope on those pins would see it.

use core::sync::atomic::{AtomicU16, Ordering};

use embedded_io_async::Read;
use laser_app::app::{
    Console, Indicators, Leds, NoHangUp, StopButton, WATCHDOG_TIMEOUT_US, Watchdog,
};
use laser_app::laser_gate::{GateState, LaserGate};
use laser_app::sequencer::{LaserEvent, LaserPower, LaserSwitch};

use crate::log_channel;
use crate::mmio::Reg;
use crate::uart::Uart;

/// The emulated laser output's level, ‰ of full (0: dark).
static LASER_LEVEL: AtomicU16 = AtomicU16::new(0);

/// Drives the emulated laser output, reporting each change on the log
/// channel: `@laser 0` dark, `@laser 1 <‰>` lit at that duty (as a PWM
/// output's compare value would show).
pub fn drive_laser_pin(power: LaserPower) {
    let level = power.per_mille();
    if LASER_LEVEL.swap(level, Ordering::AcqRel) != level {
        if power.is_on() {
            log_channel::line(format_args!("@laser 1 {level}"));
        } else {
            log_channel::line(format_args!("@laser 0"));
        }
    }
}

/// The master laser gate; closing it pulls the pin low at once.
pub static LASER_GATE: LaserGate = LaserGate::with_hook(laser_gate_changed);

/// The gate's hook: pin low when it closes, whoever holds the pin.
fn laser_gate_changed(state: GateState) {
    if !state.open {
        drive_laser_pin(LaserPower::OFF);
    }
}

/// The laser output, ANDed with the master gate (as the STM32's PB0).
pub struct LaserPin {
    /// The master gate.
    pub gate: &'static LaserGate,
}

impl LaserSwitch for LaserPin {
    fn set(&mut self, power: LaserPower) {
        if power.is_on() && self.gate.is_open() {
            drive_laser_pin(power);
            // A close between the check and the write has already run its
            // hook: look again so the output cannot stay lit.
            if !self.gate.is_open() {
                drive_laser_pin(LaserPower::OFF);
            }
        } else {
            drive_laser_pin(LaserPower::OFF);
        }
    }

    /// Reports the sequencer's laser-deciding events (`@event …`), so the
    /// host checks the same safety rules as the simulator's recorder.
    fn note(&mut self, event: LaserEvent<'_>) {
        match event {
            LaserEvent::Stopped { why } => log_channel::line(format_args!("@event stopped {why}")),
            LaserEvent::RunStarted => log_channel::line(format_args!("@event run-started")),
            LaserEvent::GimbalMoveSent => log_channel::line(format_args!("@event move-sent")),
            LaserEvent::GimbalArrived => log_channel::line(format_args!("@event arrived")),
        }
    }
}

/// The command line on UART0 (always connected: a serial line has no
/// connection state).
pub struct UartConsole {
    /// UART0, receive side.
    pub rx: Uart,
    /// UART0, transmit side.
    pub tx: Uart,
}

impl Console for UartConsole {
    type Rx = Uart;
    type Tx = Uart;
    type Presence = NoHangUp;

    async fn connected(&mut self) -> (&mut Uart, &mut Uart) {
        (&mut self.rx, &mut self.tx)
    }

    /// A UART without modem lines cannot tell.
    fn presence(&self) -> NoHangUp {
        NoHangUp
    }
}

/// The status LEDs, reported on the log channel when they change
/// (`@leds heartbeat=… laser=… fault=…`).
pub struct ReportedLeds {
    /// What was reported last.
    pub shown: Option<Leds>,
}

impl Indicators for ReportedLeds {
    fn show(&mut self, leds: Leds) {
        if self.shown != Some(leds) {
            self.shown = Some(leds);
            log_channel::line(format_args!(
                "@leds heartbeat={} laser={} fault={}",
                u8::from(leds.heartbeat),
                u8::from(leds.laser),
                u8::from(leds.fault)
            ));
        }
    }
}

/// The byte the host sends on the log channel's input to press the stop
/// button (`@button` in a script).
pub const BUTTON_BYTE: u8 = b'B';
/// The byte that asks for the CPU and stack report (`@stats` line).
pub const STATS_BYTE: u8 = b'S';

/// The stop button: [`BUTTON_BYTE`] arriving on UART2 (the host's
/// `@button`). [`STATS_BYTE`] there asks for the board's measurements
/// (`crate::stats`); other bytes are ignored.
pub struct UartButton {
    /// UART2, receive side.
    pub rx: Uart,
}

impl StopButton for UartButton {
    async fn pressed(&mut self) {
        let mut byte = [0u8];
        loop {
            if let Ok(1) = self.rx.read(&mut byte).await {
                match byte[0] {
                    BUTTON_BYTE => return,
                    STATS_BYTE => crate::stats::report(),
                    _ => {}
                }
            }
        }
    }
}

/// The CMSDK APB watchdog (0x4000_8000, 25 MHz): its counter runs down
/// from LOAD twice — the first time it raises NMI (the handler turns the
/// laser off and waits), the second time it resets the board — so LOAD is
/// half of [`WATCHDOG_TIMEOUT_US`].
pub struct CmsdkWatchdog;

const WDOG_BASE: usize = 0x4000_8000;
const WDOG_LOAD: Reg = Reg(WDOG_BASE);
const WDOG_CONTROL: Reg = Reg(WDOG_BASE + 0x08);
const WDOG_INTCLR: Reg = Reg(WDOG_BASE + 0x0C);
const WDOG_LOCK: Reg = Reg(WDOG_BASE + 0xC00);
/// LOCK: the value that unlocks the registers.
const WDOG_UNLOCK: u32 = 0x1ACC_E551;
/// CONTROL: interrupt (NMI) enable | reset enable.
const WDOG_RUN: u32 = 0b11;
/// Watchdog clock ticks per µs.
const WDOG_TICKS_PER_US: u32 = 25;

impl Watchdog for CmsdkWatchdog {
    fn start(&mut self) {
        WDOG_LOCK.write(WDOG_UNLOCK);
        WDOG_LOAD.write(WATCHDOG_TIMEOUT_US / 2 * WDOG_TICKS_PER_US);
        WDOG_CONTROL.write(WDOG_RUN);
        WDOG_LOCK.write(0);
    }

    fn feed(&mut self) {
        WDOG_LOCK.write(WDOG_UNLOCK);
        WDOG_INTCLR.write(1);
        WDOG_LOCK.write(0);
    }
}
