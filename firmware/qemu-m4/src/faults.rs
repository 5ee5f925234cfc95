//! Panic, HardFault and watchdog-warning (NMI) handlers: laser off first,
//! then a line on the log channel, then wait for the watchdog's reset (the
//! laser stays off through it).

use cortex_m_rt::{ExceptionFrame, exception};

use crate::log_channel;
use crate::parts::drive_laser_pin;

/// Laser off, log `what`, halt until the watchdog resets the board.
fn laser_off_and_halt(what: core::fmt::Arguments<'_>) -> ! {
    drive_laser_pin(laser_app::sequencer::LaserPower::OFF);
    log_channel::line(what);
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
    match info.location() {
        Some(at) => laser_off_and_halt(format_args!(
            "ERROR panic at {}:{}; laser off",
            at.file(),
            at.line()
        )),
        None => laser_off_and_halt(format_args!("ERROR panic; laser off")),
    }
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    laser_off_and_halt(format_args!(
        "ERROR hard fault at pc {:#010x}; laser off",
        frame.pc()
    ))
}

/// The watchdog's first timeout: the application stopped feeding it. The
/// second one resets the board.
#[exception]
unsafe fn NonMaskableInt() {
    laser_off_and_halt(format_args!(
        "ERROR watchdog not fed: laser off, reset follows"
    ))
}
