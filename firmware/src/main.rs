//! Laser pointing controller firmware for the STM32F4DISCOVERY.
//!
//! Boot: clocks (board::clock_config), laser GPIO low, then the tasks:
//! USB device + command-line console → command channel → sequencer.
#![no_std]
#![no_main]

mod board;
mod tasks;

use defmt_rtt as _;
use embassy_executor::Spawner;
use embassy_stm32::gpio::{Level, Output, Speed};
use embassy_stm32::{bind_interrupts, peripherals, usb};
use embassy_usb::class::cdc_acm::{CdcAcmClass, State};
use laser_app::command::CommandLink;
use panic_probe as _;
use static_cell::StaticCell;

bind_interrupts!(struct Irqs {
    OTG_FS => usb::InterruptHandler<peripherals::USB_OTG_FS>;
});

/// Console ↔ sequencer channels.
static COMMAND_LINK: CommandLink = CommandLink::new();

/// USB full-speed bulk packet size, bytes.
const USB_PACKET_BYTES: u16 = 64;

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    let p = embassy_stm32::init(board::clock_config());
    // Laser off before anything else can run.
    let _laser = Output::new(p.PB0, Level::Low, Speed::Low);
    defmt::info!(
        "{} {} (git {}) booting at {} MHz",
        laser_app::build_info::PRODUCT,
        laser_app::build_info::VERSION,
        laser_app::build_info::GIT_REV,
        board::SYSCLK_HZ / 1_000_000
    );

    // USB CDC-ACM on OTG FS (PA12 DP, PA11 DM).
    static EP_OUT_BUFFER: StaticCell<[u8; 256]> = StaticCell::new();
    let mut usb_config = usb::Config::default();
    // PA9 (VBUS) sensing is not wired on every board revision; the board is
    // bus-powered from the USB port in normal use.
    usb_config.vbus_detection = false;
    let driver = usb::Driver::new_fs(
        p.USB_OTG_FS,
        Irqs,
        p.PA12,
        p.PA11,
        EP_OUT_BUFFER.init([0; 256]),
        usb_config,
    );
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
    static RX_BUFFER: StaticCell<[u8; USB_PACKET_BYTES as usize]> = StaticCell::new();
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
    let (tx, rx) = class.split();
    let rx = rx.into_buffered(RX_BUFFER.init([0; USB_PACKET_BYTES as usize]));

    let heartbeat_led = Output::new(p.PD12, Level::Low, Speed::Low);

    spawner.spawn(tasks::usb_device(device).expect("spawn usb_device"));
    spawner.spawn(tasks::usb_console(tx, rx, &COMMAND_LINK).expect("spawn usb_console"));
    spawner.spawn(tasks::sequencer(&COMMAND_LINK).expect("spawn sequencer"));
    spawner.spawn(tasks::heartbeat(heartbeat_led).expect("spawn heartbeat"));
}
