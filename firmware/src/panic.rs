//! Panic and HardFault handlers: laser off first (the galvo's sample clock
//! and laser stream stopped, the laser PWM channel forced low, then the
//! pin low, straight through the registers, as nothing else can be
//! trusted), then log and halt. The
//! watchdog then resets the MCU; the laser stays off through reset.
//!
//! The image is linked with flip-link (`.cargo/config.toml`): the stack sits
//! below `.data`/`.bss` at the bottom of RAM, so a stack overflow runs off
//! the start of RAM and faults instead of overwriting statics. The HardFault
//! handler therefore cannot use the stack it was entered with: it switches
//! the laser off without touching the stack, restarts the stack at its top
//! and only then logs.

use core::sync::atomic::{AtomicBool, Ordering};

use embassy_stm32::pac;

/// Address of GPIOB's bit set/reset register (RM0090 §8.4.7), for the
/// HardFault handler's assembly.
pub const GPIOB_BSRR: u32 = 0x4002_0418;
/// Address of TIM8's control register 1 (RM0090 §17.4.1): writing 0 stops
/// the galvo's sample clock, so neither DMA stream gets another request.
pub const TIM8_CR1: u32 = 0x4001_0400;
/// Address of DMA2 stream 1's configuration register (RM0090 §10.5.5,
/// 0x10 + 0x18 · stream): writing 0 disables the galvo's laser stream.
pub const DMA2_S1CR: u32 = 0x4002_6428;

/// Set by the panic handler: its `udf` ends in the HardFault handler, which
/// then has nothing new to report.
static PANICKED: AtomicBool = AtomicBool::new(false);

/// Laser off now: the galvo's sample clock and laser stream stopped (no
/// queued BSRR word can set the pin again), then one store to GPIOB's bit
/// set/reset register (atomic, no read-modify-write, no stack use once
/// inlined), whatever state the program is in. Shared by the panic and
/// HardFault handlers.
#[inline(always)]
fn laser_off_now() {
    pac::TIM8.cr1().write(|_| {});
    pac::DMA2.st(1).cr().write(|_| {});
    // The laser PWM's channel forced low (PB0 may be on AF2, TIM3_CH3).
    // SAFETY: a plain store of a valid CCMR2 value to TIM3's register.
    unsafe { core::ptr::write_volatile(TIM3_CCMR2 as *mut u32, CCMR2_FORCE_INACTIVE) };
    pac::GPIOB.bsrr().write(|w| w.set_br(LASER_PIN_BIT, true));
}
use crate::laser_pwm::{CCMR2_FORCE_INACTIVE, LASER_PIN_BIT, TIM3_CCMR2};

#[panic_handler]
fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
    laser_off_now();
    PANICKED.store(true, Ordering::Relaxed);
    // The location only: formatting the message would keep every panic
    // message of the image (and core's formatting machinery) in flash.
    match info.location() {
        Some(at) => defmt::error!("panic at {}:{}", at.file(), at.line()),
        None => defmt::error!("panic"),
    }
    cortex_m::asm::udf()
}

// Top of the stack (cortex-m-rt's link.x; flip-link places it just below
// `.data`).
unsafe extern "C" {
    static _stack_start: u32;
}

/// HardFault, also reached by a stack overflow. Naked: no prologue may push
/// onto the stack before the laser is off (with an overflowed stack that
/// push would fault again and lock the core up with the laser as it was).
/// Then a fresh stack at its top for the log.
///
/// Defined as the `HardFault` vector symbol itself (cortex-m-rt's link
/// script only provides a default when the image has none): the
/// `#[exception]` macro requires a Rust-ABI function, which cannot be naked
/// on stable Rust.
#[unsafe(no_mangle)]
#[unsafe(naked)]
#[unsafe(link_section = ".HardFault.user")]
unsafe extern "C" fn HardFault() -> ! {
    core::arch::naked_asm!(
        // TIM8 and the laser stream off, then GPIOB BSRR: reset bit of
        // the laser pin (see `laser_off_now`).
        "movs r1, #0",
        "ldr r0, ={tim8_cr1}",
        "str r1, [r0]",
        "ldr r0, ={dma2_s1cr}",
        "str r1, [r0]",
        // The laser PWM channel (TIM3_CH3) forced inactive.
        "ldr r0, ={tim3_ccmr2}",
        "ldr r1, ={force_inactive}",
        "str r1, [r0]",
        "ldr r0, ={bsrr}",
        "ldr r1, ={reset_laser}",
        "str r1, [r0]",
        "ldr r0, ={top}",
        "msr MSP, r0",
        "b {log}",
        tim8_cr1 = const TIM8_CR1,
        dma2_s1cr = const DMA2_S1CR,
        tim3_ccmr2 = const TIM3_CCMR2,
        force_inactive = const CCMR2_FORCE_INACTIVE,
        bsrr = const GPIOB_BSRR,
        reset_laser = const 1u32 << (16 + LASER_PIN_BIT),
        top = sym _stack_start,
        log = sym hard_fault_log_and_halt,
    )
}

/// Logs the fault (unless it is the end of a panic, already logged) and
/// halts until the watchdog resets the MCU.
extern "C" fn hard_fault_log_and_halt() -> ! {
    if !PANICKED.load(Ordering::Relaxed) {
        let cfsr = cortex_m::peripheral::SCB::PTR;
        // SAFETY: read-only access to the fault status registers.
        let (status, address) = unsafe { ((*cfsr).cfsr.read(), (*cfsr).bfar.read()) };
        defmt::error!(
            "hard fault (CFSR {=u32:#010x}, BFAR {=u32:#010x}); laser off",
            status,
            address
        );
    }
    // A fault inside the HardFault handler locks the core up: halted, laser
    // off, until the watchdog resets it.
    cortex_m::asm::udf()
}
