//! CMSDK APB timer 0 of the MPS2 board (0x4000_0000): a 32-bit down-counter
//! at the 25 MHz peripheral clock. Under QEMU `-icount shift=0` one tick is
//! 40 guest instructions (calibrated every run).

const BASE: usize = 0x4000_0000;
const CTRL: *mut u32 = BASE as *mut u32;
const VALUE: *mut u32 = (BASE + 0x04) as *mut u32;
const RELOAD: *mut u32 = (BASE + 0x08) as *mut u32;

/// Starts the timer free-running from 0xFFFF_FFFF.
pub fn start() {
    // SAFETY: the timer's registers on the MPS2 AN386 memory map; nothing
    // else in this program uses the timer.
    unsafe {
        RELOAD.write_volatile(u32::MAX);
        VALUE.write_volatile(u32::MAX);
        CTRL.write_volatile(1);
    }
}

/// The counter now (counts down).
#[inline(always)]
pub fn now() -> u32 {
    // SAFETY: a read of the timer's VALUE register.
    unsafe { VALUE.read_volatile() }
}
