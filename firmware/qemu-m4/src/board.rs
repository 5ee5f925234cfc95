//! The board: QEMU's `mps2-an386` (ARM MPS2 FPGA with a Cortex-M4F) and the
//! [`Board`] the application is wired onto (`laser_app::app::wire`).
//!
//! | function              | peripheral                                   |
//! |-----------------------|----------------------------------------------|
//! | console               | UART0 0x4000_4000 (IRQ 0 rx, 1 tx)           |
//! | servo bus (FashionStar)| UART1 0x4000_5000 (IRQ 2/3)                 |
//! | log channel, stop button | UART2 0x4000_6000 (IRQ 4/5)               |
//! | defmt logs (`defmt-log`) | UART3 0x4000_7000 (polled)                |
//! | PELCO port (PELCO-D/P)  | UART4 0x4000_9000 (IRQ 20/21)             |
//! | embassy-time          | APB timers 0/1 0x4000_0000/0x4000_1000 (IRQ 8/9) |
//! | watchdog              | CMSDK watchdog 0x4000_8000 (NMI, then reset) |
//! | laser pin, LEDs       | reported on the log channel                  |
//! | laser controls (feature `laser-controls`) | interlock/key bytes on UART2's input, indicator reported on the log channel |
//! | settings              | top 64 KiB of RAM (survives a board reset)   |
//!
//! QEMU connects each UART to a chardev (`cargo xtask qemu`: Unix sockets
//! served by the host tool).

#[cfg(not(feature = "galvo-dac"))]
use laser_app::app::NoGalvoDac;
use laser_app::app::{Board, Parts};

use crate::parts::{CmsdkWatchdog, LASER_GATE, LaserPin, ReportedLeds, UartButton, UartConsole};
use crate::settings_ram::{RamSettings, settings_store};
use crate::uart::{UART0, UART1, UART2, UART4, Uart};

/// The board's parts, configured (laser off).
pub struct QemuBoard {
    console: UartConsole,
    servo: Uart,
    button: UartButton,
    settings: RamSettings,
    pelco: Uart,
}

impl Board for QemuBoard {
    type Console = UartConsole;
    type ServoRx = Uart;
    type ServoTx = Uart;
    type Laser = LaserPin;
    type Settings = RamSettings;
    // Without the `galvo-dac` feature no DAC is modelled and no galvo loop
    // runs (as on the STM32 board today).
    #[cfg(not(feature = "galvo-dac"))]
    type GalvoDac = NoGalvoDac;
    #[cfg(feature = "galvo-dac")]
    type GalvoDac = crate::galvo_dac::QemuDac;
    type Indicators = ReportedLeds;
    type StopButton = UartButton;
    type Watchdog = CmsdkWatchdog;
    type Stepper = laser_app::app::NoStepper;
    #[cfg(not(feature = "laser-controls"))]
    type LaserControls = laser_app::app::NoLaserControls;
    #[cfg(feature = "laser-controls")]
    type LaserControls = crate::controls::ChannelLaserControls;
    type PelcoRx = Uart;
    type PelcoTx = Uart;

    fn into_parts(self) -> Parts<Self> {
        Parts {
            console: self.console,
            servo_rx: self.servo,
            servo_tx: self.servo,
            laser: LaserPin { gate: &LASER_GATE },
            settings: self.settings,
            #[cfg(not(feature = "galvo-dac"))]
            galvo_dac: None,
            #[cfg(feature = "galvo-dac")]
            galvo_dac: Some(crate::galvo_dac::QemuDac::new()),
            indicators: ReportedLeds { shown: None },
            stop_button: self.button,
            watchdog: CmsdkWatchdog,
            stepper: None,
            #[cfg(not(feature = "laser-controls"))]
            laser_controls: None,
            #[cfg(feature = "laser-controls")]
            laser_controls: Some(crate::controls::ChannelLaserControls { shown: None }),
            pelco: Some((self.pelco, self.pelco)),
        }
    }
}

/// Brings the board up (the log channel is up already): the console and
/// servo UARTs, the PELCO port's and the settings store.
pub fn init() -> QemuBoard {
    let console = Uart::start(&UART0);
    QemuBoard {
        console: UartConsole {
            rx: console,
            tx: console,
        },
        servo: Uart::start(&UART1),
        button: UartButton {
            rx: Uart::start(&UART2),
        },
        settings: settings_store(),
        pelco: Uart::start(&UART4),
    }
}
