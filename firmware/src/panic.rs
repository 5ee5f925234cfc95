//! Panic handler: laser off first (straight through the GPIO registers, as
//! nothing else can be trusted in a panic), then log and halt. The watchdog
//! then resets the MCU; the laser stays off through reset.

use core::panic::PanicInfo;

use embassy_stm32::pac;

use crate::board::LASER_PIN_BIT;

#[panic_handler]
fn panic(info: &PanicInfo<'_>) -> ! {
    pac::GPIOB.bsrr().write(|w| w.set_br(LASER_PIN_BIT, true));
    defmt::error!("panic: {}", defmt::Display2Format(info));
    cortex_m::asm::udf()
}
