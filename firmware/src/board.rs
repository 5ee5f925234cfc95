//! Board layer for the STM32F4DISCOVERY (STM32F407VG): clocks and every pin
//! choice in one place. Porting to another STM32 means changing this file
//! (and `memory.x`).
//!
//! | function            | pin(s)            |
//! |---------------------|-------------------|
//! | USB OTG FS (CDC-ACM)| PA11 DM, PA12 DP  |
//! | servo bus USART2    | PA2 TX, PA3 RX    |
//! | galvo DAC1 X / Y    | PA4 / PA5         |
//! | laser enable        | PB0 (active high) |
//! | LEDs                | PD12 green heartbeat, PD13 orange laser, PD14 red fault, PD15 blue USB |
//! | user button         | PA0 (stop + laser off) |

use embassy_stm32::Config;
use embassy_stm32::time::Hertz;

/// System clock, Hz (from the 8 MHz HSE crystal through the PLL).
pub const SYSCLK_HZ: u32 = 168_000_000;

/// Clock tree: 8 MHz HSE → PLL → 168 MHz SYSCLK, 48 MHz for USB,
/// APB1 42 MHz (timers 84 MHz), APB2 84 MHz (timers 168 MHz).
pub fn clock_config() -> Config {
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
