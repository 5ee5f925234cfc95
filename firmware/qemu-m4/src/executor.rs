//! A thread-mode executor that sleeps with WFI. QEMU treats WFE (what
//! embassy's cortex-m executor sleeps with) as a plain yield, so that
//! executor spins at 100 % host CPU; WFI sleeps until an interrupt, and
//! under `-icount` virtual time then follows host time.

use core::sync::atomic::{AtomicBool, Ordering};

use embassy_executor::{Spawner, raw};
use static_cell::StaticCell;

/// A task was woken: poll before sleeping again.
static WOKEN: AtomicBool = AtomicBool::new(false);

/// Called by embassy when a task is woken (from a task or an interrupt
/// handler): the next loop polls instead of sleeping.
#[unsafe(export_name = "__pender")]
fn pender(_context: *mut ()) {
    WOKEN.store(true, Ordering::Release);
}

/// Runs `init` (which spawns the tasks), then polls the tasks whenever one
/// was woken and sleeps in WFI otherwise; never returns.
pub fn run(init: impl FnOnce(Spawner)) -> ! {
    static EXECUTOR: StaticCell<raw::Executor> = StaticCell::new();
    let executor: &'static raw::Executor = EXECUTOR.init(raw::Executor::new(core::ptr::null_mut()));
    init(executor.spawner());
    loop {
        // Interrupts off between the check and WFI, so a wake-up in
        // between is not slept through: WFI still wakes on a pending
        // interrupt, which runs as soon as they are on again.
        cortex_m::interrupt::disable();
        if !WOKEN.swap(false, Ordering::AcqRel) {
            let asleep_from = crate::time_driver::timer_ticks();
            cortex_m::asm::wfi();
            crate::stats::slept(crate::time_driver::timer_ticks() - asleep_from);
        }
        // SAFETY: enabling interrupts in thread mode outside any critical
        // section (none is held here).
        unsafe { cortex_m::interrupt::enable() };
        // SAFETY: this executor is only ever polled from this loop.
        unsafe { executor.poll() };
    }
}
