//! embassy-time driver on the board's two CMSDK APB timers (25 MHz
//! peripheral clock, 32-bit down-counters): timer 0 runs free and its wrap
//! interrupt extends it to 64 bits (the time base); timer 1 is the alarm,
//! loaded with the time to the next deadline. Ticks are embassy-time's
//! default 1 MHz (1 µs).

use core::cell::{Cell, RefCell};
use core::task::Waker;

use critical_section::{CriticalSection, Mutex};
use embassy_time_driver::Driver;
use embassy_time_queue_utils::Queue;

use crate::interrupts::{self, Irq};
use crate::mmio::Reg;

/// Timer clock, Hz (the MPS2's 25 MHz peripheral clock).
const TIMER_HZ: u64 = 25_000_000;
/// Timer ticks per embassy tick (1 µs).
const TIMER_TICKS_PER_US: u64 = TIMER_HZ / 1_000_000;
/// Longest alarm loaded at once, timer ticks (a later deadline is reached
/// in steps).
const MAX_ALARM_TICKS: u64 = 1 << 31;

/// One CMSDK APB timer's registers.
struct Timer {
    base: usize,
}

/// CTRL: enable.
const CTRL_ENABLE: u32 = 1 << 0;
/// CTRL: interrupt on reaching zero.
const CTRL_IRQ: u32 = 1 << 3;

impl Timer {
    const fn reg(&self, offset: usize) -> Reg {
        Reg(self.base + offset)
    }
    const fn ctrl(&self) -> Reg {
        self.reg(0x00)
    }
    const fn value(&self) -> Reg {
        self.reg(0x04)
    }
    const fn reload(&self) -> Reg {
        self.reg(0x08)
    }
    /// INTSTATUS on read, INTCLEAR on write.
    const fn int(&self) -> Reg {
        self.reg(0x0C)
    }
}

/// The time base.
const TIMER0: Timer = Timer { base: 0x4000_0000 };
/// The alarm.
const TIMER1: Timer = Timer { base: 0x4000_1000 };

/// The driver: wraps of timer 0 so far and the timer queue.
struct CmsdkTimeDriver {
    wraps: Mutex<Cell<u32>>,
    queue: Mutex<RefCell<Queue>>,
}

embassy_time_driver::time_driver_impl!(static DRIVER: CmsdkTimeDriver = CmsdkTimeDriver {
    wraps: Mutex::new(Cell::new(0)),
    queue: Mutex::new(RefCell::new(Queue::new())),
});

/// Starts the time base and enables both timers' interrupts.
pub fn init() {
    TIMER0.ctrl().write(0);
    TIMER0.reload().write(u32::MAX);
    TIMER0.value().write(u32::MAX);
    TIMER0.int().write(1);
    TIMER0.ctrl().write(CTRL_ENABLE | CTRL_IRQ);
    TIMER1.ctrl().write(0);
    TIMER1.int().write(1);
    interrupts::enable(Irq::Timer0);
    interrupts::enable(Irq::Timer1);
}

impl CmsdkTimeDriver {
    /// Timer-0 ticks since [`init`].
    fn timer_ticks(&self, cs: CriticalSection<'_>) -> u64 {
        let mut wraps = self.wraps.borrow(cs).get();
        let mut value = TIMER0.value().read();
        // A wrap whose interrupt has not run yet: the value read may be
        // from either side of it, so read it again (now after the wrap).
        if TIMER0.int().read() & 1 != 0 {
            value = TIMER0.value().read();
            wraps = wraps.wrapping_add(1);
        }
        (u64::from(wraps) << 32) | u64::from(u32::MAX - value)
    }

    fn now_us(&self, cs: CriticalSection<'_>) -> u64 {
        self.timer_ticks(cs) / TIMER_TICKS_PER_US
    }

    /// Loads the alarm for `at` µs; `false` when `at` has already passed
    /// (the caller then wakes what is due and asks again).
    fn set_alarm(&self, cs: CriticalSection<'_>, at: u64) -> bool {
        TIMER1.ctrl().write(0);
        TIMER1.int().write(1);
        if at == u64::MAX {
            return true;
        }
        let now = self.now_us(cs);
        if at <= now {
            return false;
        }
        let ticks = ((at - now) * TIMER_TICKS_PER_US).min(MAX_ALARM_TICKS) as u32;
        TIMER1.reload().write(ticks);
        TIMER1.value().write(ticks);
        TIMER1.ctrl().write(CTRL_ENABLE | CTRL_IRQ);
        true
    }

    /// Wakes the timers that are due and loads the alarm for the next.
    fn rearm(&self, cs: CriticalSection<'_>) {
        let mut queue = self.queue.borrow(cs).borrow_mut();
        let mut next = queue.next_expiration(self.now_us(cs));
        while !self.set_alarm(cs, next) {
            next = queue.next_expiration(self.now_us(cs));
        }
    }
}

impl Driver for CmsdkTimeDriver {
    fn now(&self) -> u64 {
        critical_section::with(|cs| self.now_us(cs))
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        critical_section::with(|cs| {
            let earliest = self.queue.borrow(cs).borrow_mut().schedule_wake(at, waker);
            if earliest {
                self.rearm(cs);
            }
        });
    }
}

/// Timer-0 ticks (25 MHz, 40 ns: 40 instructions under `-icount
/// shift=0`) since [`init`].
pub fn timer_ticks() -> u64 {
    critical_section::with(|cs| DRIVER.timer_ticks(cs))
}

/// Timer 0 wrapped: one more period of the time base.
pub unsafe extern "C" fn timer0_wrapped() {
    critical_section::with(|cs| {
        if TIMER0.int().read() & 1 != 0 {
            TIMER0.int().write(1);
            let wraps = DRIVER.wraps.borrow(cs);
            wraps.set(wraps.get().wrapping_add(1));
        }
    });
}

/// The alarm went off: wake what is due, load the next alarm.
pub unsafe extern "C" fn timer1_alarm() {
    critical_section::with(|cs| {
        TIMER1.ctrl().write(0);
        TIMER1.int().write(1);
        DRIVER.rearm(cs);
    });
}
