//! Board layer for the STM32F4DISCOVERY (STM32F407VG): clocks and every pin
//! choice in one place, and the [`Board`] the application is wired onto
//! (`laser_app::app::wire`). Porting to another STM32 means changing this
//! file, `parts.rs` (and `memory.x`).
//!
//! | function            | pin(s)            |
//! |---------------------|-------------------|
//! | USB OTG FS (CDC-ACM)| PA11 DM, PA12 DP  |
//! | servo bus USART2    | PA2 TX, PA3 RX (interrupt-driven, no DMA) |
//! | galvo DAC1 X / Y    | PA4 / PA5, dual channel, TIM8-triggered, DMA1 stream 5 ch 7 |
//! | laser enable / power | PB0 (active high): TIM3_CH3 PWM (AF2, 1 kHz) for a power level, GPIO when dark or full (`laser_pwm`); galvo laser stream DMA2 stream 1 ch 7 (TIM8_UP) |
//! | LEDs                | PD12 green heartbeat, PD13 orange laser, PD14 red fault, PD15 blue USB |
//! | user button         | PA0 (stop + laser off) |
//! | laser controls      | PD1 remote interlock, PD2 key switch (pull-up inputs, EXTI1/EXTI2; closed to GND = closed / on), PD3 emission indicator (active high) — `docs/laser-safety.md` |
//! | stepper pan STEP / DIR  | PE9 TIM1_CH1 (AF1, one-pulse: the pulse timed by TIM1) / PE10 GPIO (the step events on an interrupt executor, `tasks.rs`) |
//! | stepper tilt STEP / DIR | PE11 TIM1_CH2 (AF1, one-pulse) / PE12 GPIO |
//! | stepper ENABLE (both)   | PE13 (polarity a parameter; released = the idle level) |
//! | stepper limit switches  | PE7 pan, PE8 tilt (pull-up inputs, normally-open switch to GND: low = pressed) |
//! | PELCO port USART3 (RS-485) | PB10 TX, PB11 RX (interrupt-driven, buffered; baud `pelco.baud`, 8N1), PB12 driver enable (high while sending, `rs485.rs`) — `docs/pelco.md` |
//!
//! Flash: the image in sectors 0–6 (≤ 384 KiB), the saved settings in
//! sectors 10 and 11 (`settings_flash`, `memory.x`).
//!
//! DMA: DAC1 channel 1's request is DMA1 stream 5, where USART2's receive
//! request also sits, so the servo UART is interrupt-driven (buffered)
//! instead. Interrupt priorities: every peripheral interrupt at P0 (short
//! handlers), the galvo executor at [`GALVO_PRIORITY`] below them and above
//! thread mode (USB, sequencer, servo bus).

use core::sync::atomic::AtomicBool;
use embassy_executor::Spawner;
use embassy_stm32::exti::ExtiInput;
use embassy_stm32::flash::{self, Flash};
use embassy_stm32::gpio::{Input, Level, Output, Pull, Speed};
use embassy_stm32::interrupt::Priority;
use embassy_stm32::peripherals::{
    PA2, PA3, PA11, PA12, PB10, PB11, PB12, USART2, USART3, USB_OTG_FS,
};
use embassy_stm32::time::Hertz;
use embassy_stm32::usart::{self, BufferedUart, BufferedUartRx, BufferedUartTx};
use embassy_stm32::{Peri, bind_interrupts, exti, pac, peripherals, usb};
use embassy_time::Instant;
use embassy_usb::UsbDevice;
use embassy_usb::class::cdc_acm::{CdcAcmClass, State};
use laser_app::app::{Board, Parts};
use static_cell::StaticCell;

use crate::galvo_dac::{GalvoDacPeripherals, HalfInterrupt, Stm32GalvoDac};
use crate::laser_gate::LASER_GATE;
use crate::laser_pwm::{LASER_PIN_BIT, LaserPin};
use crate::parts::{
    IndependentDog, LaserControlPins, StatusLeds, TimerStepper, UsbConsole, UsbDriver, UsbDtr,
    UserButton,
};
use crate::rs485::Rs485Tx;
use crate::settings_flash::{FlashSettings, settings_store};

bind_interrupts!(struct Irqs {
    OTG_FS => usb::InterruptHandler<peripherals::USB_OTG_FS>;
    USART2 => usart::BufferedInterruptHandler<peripherals::USART2>;
    USART3 => usart::BufferedInterruptHandler<peripherals::USART3>;
    DMA1_STREAM5 => HalfInterrupt;
    EXTI0 => exti::InterruptHandler<embassy_stm32::interrupt::typelevel::EXTI0>;
    EXTI1 => exti::InterruptHandler<embassy_stm32::interrupt::typelevel::EXTI1>;
    EXTI2 => exti::InterruptHandler<embassy_stm32::interrupt::typelevel::EXTI2>;
    FLASH => flash::InterruptHandler;
});

/// USB full-speed bulk packet size, bytes.
const USB_PACKET_BYTES: u16 = 64;
/// Servo bus baud rate (FashionStar default).
const SERVO_BAUD: u32 = 115_200;
/// Servo UART software buffers, bytes each way.
const SERVO_BUFFER_BYTES: usize = 256;
/// PELCO UART software buffers, bytes each way (a frame is 7 or 8; a
/// keyboard repeats its frames every ~50–100 ms).
const PELCO_BUFFER_BYTES: usize = 64;

/// Priority of the galvo executor's interrupt: below every peripheral
/// interrupt (P0: the DMA half interrupt, USART2, USB, the time driver),
/// above thread mode.
pub const GALVO_PRIORITY: Priority = Priority::P1;

/// System clock, Hz (from the 8 MHz HSE crystal through the PLL).
pub const SYSCLK_HZ: u32 = 168_000_000;

/// Clock tree: 8 MHz HSE → PLL → 168 MHz SYSCLK, 48 MHz for USB,
/// APB1 42 MHz (timers 84 MHz), APB2 84 MHz (timers 168 MHz).
pub fn clock_config() -> embassy_stm32::Config {
    use embassy_stm32::rcc::*;
    let mut config = embassy_stm32::Config::default();
    config.rcc.hse = Some(Hse {
        freq: Hertz(8_000_000),
        mode: HseMode::Oscillator,
    });
    config.rcc.pll_src = PllSource::HSE;
    config.rcc.pll = Some(Pll {
        prediv: PllPreDiv::DIV4,   // 2 MHz VCO input
        mul: PllMul::MUL168,       // 336 MHz VCO
        divp: Some(PllPDiv::DIV2), // 168 MHz SYSCLK
        divq: Some(PllQDiv::DIV7), // 48 MHz USB
        divr: None,
    });
    config.rcc.ahb_pre = AHBPrescaler::DIV1;
    config.rcc.apb1_pre = APBPrescaler::DIV4;
    config.rcc.apb2_pre = APBPrescaler::DIV2;
    config.rcc.sys = Sysclk::PLL1_P;
    config.rcc.mux.clk48sel = mux::Clk48sel::PLL1_Q;
    config
}

/// The board's parts, configured (laser off).
pub struct Stm32Board {
    /// Laser enable (PB0), low.
    pub laser: LaserPin,
    /// The command line on USB CDC-ACM.
    pub console: UsbConsole,
    /// Servo UART transmit (interrupt-driven, buffered).
    pub servo_tx: BufferedUartTx<'static>,
    /// Servo UART receive (interrupt-driven, buffered).
    pub servo_rx: BufferedUartRx<'static>,
    /// The galvo DAC stream (TIM8, DAC1, DMA1 stream 5, DMA2 stream 1).
    pub galvo: Stm32GalvoDac,
    /// Heartbeat, laser and fault LEDs (PD12–PD14).
    pub leds: StatusLeds,
    /// User button (PA0).
    pub button: UserButton,
    /// Settings store (flash sectors 10 and 11).
    pub settings: FlashSettings,
    /// Independent watchdog (not started).
    pub watchdog: IndependentDog,
    /// Stepper pan/tilt driver inputs (PE9–PE13, STEP from TIM1), limit
    /// switches (PE7, PE8).
    pub stepper: TimerStepper,
    /// Remote interlock (PD1), key switch (PD2), emission indicator (PD3).
    pub laser_controls: LaserControlPins,
    /// The PELCO port: USART3 receive (PB11).
    pub pelco_rx: BufferedUartRx<'static>,
    /// The PELCO port: USART3 transmit (PB10) with the RS-485 driver
    /// enable (PB12).
    pub pelco_tx: Rs485Tx,
}

impl Board for Stm32Board {
    type Console = UsbConsole;
    type ServoRx = BufferedUartRx<'static>;
    type ServoTx = BufferedUartTx<'static>;
    type Laser = LaserPin;
    type Settings = FlashSettings;
    type GalvoDac = Stm32GalvoDac;
    type Stepper = TimerStepper;
    type Indicators = StatusLeds;
    type StopButton = UserButton;
    type Watchdog = IndependentDog;
    type LaserControls = LaserControlPins;
    type PelcoRx = BufferedUartRx<'static>;
    type PelcoTx = Rs485Tx;

    fn into_parts(self) -> Parts<Self> {
        Parts {
            console: self.console,
            servo_rx: self.servo_rx,
            servo_tx: self.servo_tx,
            laser: self.laser,
            settings: self.settings,
            galvo_dac: Some(self.galvo),
            stepper: Some(self.stepper),
            indicators: self.leds,
            stop_button: self.button,
            watchdog: self.watchdog,
            laser_controls: Some(self.laser_controls),
            pelco: Some((self.pelco_rx, self.pelco_tx)),
        }
    }
}

/// Brings the board up: laser off first, then clocks and peripherals; the
/// USB device stack runs as a task of its own from here on.
pub fn init(spawner: Spawner) -> Stm32Board {
    let p = embassy_stm32::init(clock_config());
    // Laser off before anything else can run.
    let laser = LaserPin::new(
        Output::new(p.PB0, Level::Low, Speed::Low),
        p.TIM3,
        &LASER_GATE,
    );
    defmt::info!(
        "{} {} (git {}) booting at {} MHz",
        laser_app::build_info::PRODUCT,
        laser_app::build_info::VERSION,
        laser_app::build_info::GIT_REV,
        SYSCLK_HZ / 1_000_000
    );
    let (usb_device, console) = usb_console(p.USB_OTG_FS, p.PA12, p.PA11);
    spawner.spawn(defmt::unwrap!(usb_device_task(usb_device)));
    let (servo_tx, servo_rx) = servo_uart(p.USART2, p.PA3, p.PA2);
    let (pelco_tx, pelco_rx) = pelco_uart(p.USART3, p.PB11, p.PB10, p.PB12);
    enable_cycle_counter();
    // The HardFault handler's hand-written register addresses.
    defmt::assert!(
        pac::TIM8.cr1().as_ptr() as u32 == crate::panic::TIM8_CR1
            && pac::DMA2.st(1).cr().as_ptr() as u32 == crate::panic::DMA2_S1CR
            && pac::GPIOB.bsrr().as_ptr() as u32 == crate::panic::GPIOB_BSRR
    );
    let galvo_parts = GalvoDacPeripherals {
        timer: p.TIM8,
        dac: p.DAC1,
        dac_dma: p.DMA1_CH5,
        laser_dma: p.DMA2_CH1,
        x: p.PA4,
        y: p.PA5,
    };
    let galvo = Stm32GalvoDac::new(
        galvo_parts,
        &LASER_GATE,
        LASER_PIN_BIT as u8,
        SYSCLK_HZ,
        Irqs,
    );
    Stm32Board {
        laser,
        console,
        servo_tx,
        servo_rx,
        galvo,
        leds: StatusLeds {
            heartbeat: Output::new(p.PD12, Level::Low, Speed::Low),
            laser: Output::new(p.PD13, Level::Low, Speed::Low),
            fault: Output::new(p.PD14, Level::Low, Speed::Low),
        },
        button: UserButton {
            input: ExtiInput::new(p.PA0, p.EXTI0, Pull::Down, Irqs),
            armed_from: Instant::MIN,
        },
        settings: settings_store(Flash::new(p.FLASH, Irqs)),
        watchdog: IndependentDog::new(p.IWDG),
        stepper: TimerStepper::new(
            p.TIM1,
            (p.PE9, p.PE11),
            [
                Output::new(p.PE10, Level::Low, Speed::VeryHigh),
                Output::new(p.PE12, Level::Low, Speed::VeryHigh),
            ],
            // Active-low ENABLE by default: high = released at reset.
            Output::new(p.PE13, Level::High, Speed::Low),
            [Input::new(p.PE7, Pull::Up), Input::new(p.PE8, Pull::Up)],
        ),
        laser_controls: LaserControlPins {
            interlock: ExtiInput::new(p.PD1, p.EXTI1, Pull::Up, Irqs),
            key: ExtiInput::new(p.PD2, p.EXTI2, Pull::Up, Irqs),
            indicator: Output::new(p.PD3, Level::Low, Speed::Low),
        },
        pelco_rx,
        pelco_tx,
    }
}

/// Runs the USB device stack (enumeration, control requests).
#[embassy_executor::task]
async fn usb_device_task(mut device: UsbDevice<'static, UsbDriver>) -> ! {
    device.run().await
}

/// USB CDC-ACM on OTG FS (PA12 DP, PA11 DM): the device stack and the
/// console port.
fn usb_console(
    otg: Peri<'static, USB_OTG_FS>,
    dp: Peri<'static, PA12>,
    dm: Peri<'static, PA11>,
) -> (UsbDevice<'static, UsbDriver>, UsbConsole) {
    static EP_OUT_BUFFER: StaticCell<[u8; 256]> = StaticCell::new();
    let mut usb_config = usb::Config::default();
    // VBUS sensing (PA9) is not needed: the board is powered from USB.
    usb_config.vbus_detection = false;
    let driver = usb::Driver::new_fs(otg, Irqs, dp, dm, EP_OUT_BUFFER.init([0; 256]), usb_config);
    let mut device_config = embassy_usb::Config::new(0xc0de, 0xcafe);
    device_config.manufacturer = Some("laser-pointer");
    device_config.product = Some("Laser pointing controller");
    device_config.serial_number = Some(laser_app::build_info::VERSION);
    device_config.max_power = 100;
    device_config.max_packet_size_0 = 64;

    static CONFIG_DESCRIPTOR: StaticCell<[u8; 256]> = StaticCell::new();
    static BOS_DESCRIPTOR: StaticCell<[u8; 256]> = StaticCell::new();
    static CONTROL_BUF: StaticCell<[u8; 64]> = StaticCell::new();
    static CDC_STATE: StaticCell<State> = StaticCell::new();
    static USB_RX_BUFFER: StaticCell<[u8; USB_PACKET_BYTES as usize]> = StaticCell::new();
    static USB_DTR: StaticCell<UsbDtr> = StaticCell::new();
    let mut builder = embassy_usb::Builder::new(
        driver,
        device_config,
        CONFIG_DESCRIPTOR.init([0; 256]),
        BOS_DESCRIPTOR.init([0; 256]),
        &mut [],
        CONTROL_BUF.init([0; 64]),
    );
    let class = CdcAcmClass::new(&mut builder, CDC_STATE.init(State::new()), USB_PACKET_BYTES);
    let device = builder.build();
    let (tx, rx, control) = class.split_with_control();
    let rx = rx.into_buffered(USB_RX_BUFFER.init([0; USB_PACKET_BYTES as usize]));
    let dtr = USB_DTR.init(UsbDtr {
        control,
        seen: AtomicBool::new(false),
    });
    (device, UsbConsole { tx, rx, dtr })
}

/// Servo bus: USART2 (PA2 TX, PA3 RX), interrupt-driven both ways (its
/// receive DMA request would be DMA1 stream 5, the galvo DAC's). Its
/// interrupt stays at P0, above the galvo executor: at 115 200 baud a
/// byte arrives every 87 µs and the USART holds only one.
fn servo_uart(
    usart: Peri<'static, USART2>,
    rx_pin: Peri<'static, PA3>,
    tx_pin: Peri<'static, PA2>,
) -> (BufferedUartTx<'static>, BufferedUartRx<'static>) {
    static SERVO_TX_BUFFER: StaticCell<[u8; SERVO_BUFFER_BYTES]> = StaticCell::new();
    static SERVO_RX_BUFFER: StaticCell<[u8; SERVO_BUFFER_BYTES]> = StaticCell::new();
    let buffers = (
        SERVO_TX_BUFFER.init([0; SERVO_BUFFER_BYTES]).as_mut_slice(),
        SERVO_RX_BUFFER.init([0; SERVO_BUFFER_BYTES]).as_mut_slice(),
    );
    buffered_uart(usart, rx_pin, tx_pin, buffers, SERVO_BAUD)
}

/// The PELCO port: USART3 (PB10 TX, PB11 RX), interrupt-driven both ways,
/// at the default 9600 baud 8N1 until the port task sets the saved
/// `pelco.baud`; PB12 drives the RS-485 transceiver's DE and /RE (low:
/// receiving).
fn pelco_uart(
    usart: Peri<'static, USART3>,
    rx_pin: Peri<'static, PB11>,
    tx_pin: Peri<'static, PB10>,
    de_pin: Peri<'static, PB12>,
) -> (Rs485Tx, BufferedUartRx<'static>) {
    let de = Output::new(de_pin, Level::Low, Speed::Low);
    static PELCO_TX_BUFFER: StaticCell<[u8; PELCO_BUFFER_BYTES]> = StaticCell::new();
    static PELCO_RX_BUFFER: StaticCell<[u8; PELCO_BUFFER_BYTES]> = StaticCell::new();
    let buffers = (
        PELCO_TX_BUFFER.init([0; PELCO_BUFFER_BYTES]).as_mut_slice(),
        PELCO_RX_BUFFER.init([0; PELCO_BUFFER_BYTES]).as_mut_slice(),
    );
    let (tx, rx) = buffered_uart(usart, rx_pin, tx_pin, buffers, 9600);
    (Rs485Tx { tx, de }, rx)
}

/// A USART, interrupt-driven and buffered both ways (`buffers`: transmit,
/// receive), at `baud` 8N1, split into its halves.
fn buffered_uart<T: usart::Instance>(
    usart: Peri<'static, T>,
    rx_pin: Peri<'static, impl usart::RxPin<T>>,
    tx_pin: Peri<'static, impl usart::TxPin<T>>,
    buffers: (&'static mut [u8], &'static mut [u8]),
    baud: u32,
) -> (BufferedUartTx<'static>, BufferedUartRx<'static>)
where
    Irqs: embassy_stm32::interrupt::typelevel::Binding<
            T::Interrupt,
            usart::BufferedInterruptHandler<T>,
        >,
{
    let mut uart_config = usart::Config::default();
    uart_config.baudrate = baud;
    let (tx_buffer, rx_buffer) = buffers;
    match BufferedUart::new(
        usart,
        rx_pin,
        tx_pin,
        tx_buffer,
        rx_buffer,
        Irqs,
        uart_config,
    ) {
        Ok(uart) => uart.split(),
        Err(_) => defmt::panic!("USART configuration rejected"),
    }
}

/// Starts the DWT cycle counter (the galvo refill timing).
fn enable_cycle_counter() {
    match cortex_m::Peripherals::take() {
        Some(mut core) => {
            core.DCB.enable_trace();
            core.DWT.enable_cycle_counter();
        }
        None => defmt::panic!("core peripherals already taken"),
    }
}
