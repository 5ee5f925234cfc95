//! The board's own measurements, reported on the log channel when the host
//! asks (`S` on its input): time asleep in WFI against time since boot —
//! under `-icount shift=0` the CPU runs 1 instruction per ns, so the busy
//! time is the instruction count — and, with the `stack-paint` feature, the
//! peak stack each task reached in any of its polls:
//!
//! ```text
//! 5000000 @stats ticks=125000000 slept=124000000 stack=console:1234,servo-bus:800,…
//! ```
//!
//! Stack painting: the 128 KiB below the stack top are filled with a
//! pattern at boot; after each poll of a task (embassy-executor's trace
//! hooks) the lowest word no longer holding the pattern is that poll's
//! depth, and the dirtied part is painted again.

use core::cell::Cell;

use critical_section::Mutex;

use crate::log_channel;

/// Timer ticks spent asleep in WFI.
static SLEPT_TICKS: Mutex<Cell<u64>> = Mutex::new(Cell::new(0));

/// Adds `ticks` of sleep (the executor, after each WFI).
pub fn slept(ticks: u64) {
    critical_section::with(|cs| {
        let slept = SLEPT_TICKS.borrow(cs);
        slept.set(slept.get() + ticks);
    });
}

/// Writes the `@stats` line.
pub fn report() {
    let ticks = crate::time_driver::timer_ticks();
    let slept = critical_section::with(|cs| SLEPT_TICKS.borrow(cs).get());
    log_channel::line(format_args!(
        "@stats ticks={ticks} slept={slept} stack={}",
        paint::Peaks
    ));
}

/// Paints the stack window (a no-op without `stack-paint`).
pub fn paint_stack() {
    paint::paint_window();
}

#[cfg(not(feature = "stack-paint"))]
mod paint {
    /// No peaks without painting: `stack=` stays empty.
    pub struct Peaks;

    impl core::fmt::Display for Peaks {
        fn fmt(&self, _: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
            Ok(())
        }
    }

    pub fn paint_window() {}
}

#[cfg(feature = "stack-paint")]
mod paint {
    use core::cell::RefCell;
    use core::fmt;

    use critical_section::Mutex;

    /// The pattern painted words hold.
    const PAINT: u32 = 0xDEAD_BEEF;
    /// Bytes painted below the stack top.
    const WINDOW_BYTES: usize = 128 * 1024;
    /// Task names in spawn order (`laser_app::app::wire`'s order).
    #[cfg(not(feature = "galvo-dac"))]
    const NAMES: [&str; 6] = [
        "console",
        "servo-bus",
        "sequencer",
        "indicators",
        "stop-button",
        "watchdog",
    ];
    /// Task names in spawn order (`laser_app::app::wire`'s order).
    #[cfg(feature = "galvo-dac")]
    const NAMES: [&str; 7] = [
        "console",
        "servo-bus",
        "sequencer",
        "galvo",
        "indicators",
        "stop-button",
        "watchdog",
    ];

    unsafe extern "C" {
        /// Top of the stack (cortex-m-rt; flip-link moves it below .data).
        static _stack_start: u32;
    }

    struct Tracker {
        ids: [u32; NAMES.len()],
        spawned: usize,
        peak: [u32; NAMES.len()],
        /// Depth of the deepest poll outside any task (main, idle ISRs).
        other: u32,
    }

    static TRACKER: Mutex<RefCell<Tracker>> = Mutex::new(RefCell::new(Tracker {
        ids: [0; NAMES.len()],
        spawned: 0,
        peak: [0; NAMES.len()],
        other: 0,
    }));

    fn top() -> usize {
        (&raw const _stack_start) as usize
    }

    fn floor() -> usize {
        top() - WINDOW_BYTES
    }

    /// Paints the window below the current stack pointer.
    pub fn paint_window() {
        let sp = cortex_m::register::msp::read() as usize;
        paint(floor(), sp.saturating_sub(64));
    }

    fn paint(from: usize, to: usize) {
        let mut at = from;
        while at + 4 <= to {
            // SAFETY: [floor, sp - 64) is stack below the live frames.
            unsafe { (at as *mut u32).write_volatile(PAINT) };
            at += 4;
        }
    }

    /// Bytes from the top down to the lowest word no longer painted;
    /// repaints what was dirtied.
    fn used_and_repaint() -> u32 {
        let mut at = floor();
        // SAFETY: reads of the painted window.
        while at < top() && unsafe { (at as *const u32).read_volatile() } == PAINT {
            at += 4;
        }
        let sp = cortex_m::register::msp::read() as usize;
        paint(at, sp.saturating_sub(64));
        (top() - at) as u32
    }

    fn update(task_id: Option<u32>) {
        critical_section::with(|cs| {
            let mut t = TRACKER.borrow(cs).borrow_mut();
            let used = used_and_repaint();
            match task_id.and_then(|id| t.ids[..t.spawned].iter().position(|&x| x == id)) {
                Some(i) => t.peak[i] = t.peak[i].max(used),
                None => t.other = t.other.max(used),
            }
        });
    }

    /// The peaks as `name:bytes,…`.
    pub struct Peaks;

    impl fmt::Display for Peaks {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            let (names, peaks, other) = critical_section::with(|cs| {
                let t = TRACKER.borrow(cs).borrow();
                (t.spawned, t.peak, t.other)
            });
            for (name, peak) in NAMES.iter().zip(peaks).take(names) {
                write!(f, "{name}:{peak},")?;
            }
            write!(f, "other:{other},window:{WINDOW_BYTES}")
        }
    }

    #[unsafe(no_mangle)]
    fn _embassy_trace_task_new(_executor_id: u32, task_id: u32) {
        critical_section::with(|cs| {
            let mut t = TRACKER.borrow(cs).borrow_mut();
            if t.spawned < NAMES.len() {
                let i = t.spawned;
                t.ids[i] = task_id;
                t.spawned += 1;
            }
        });
    }

    #[unsafe(no_mangle)]
    fn _embassy_trace_task_exec_begin(_executor_id: u32, _task_id: u32) {
        // What ran before this poll (the executor, interrupt handlers) is
        // not this task's.
        update(None);
    }

    #[unsafe(no_mangle)]
    fn _embassy_trace_task_exec_end(_executor_id: u32, task_id: u32) {
        update(Some(task_id));
    }

    #[unsafe(no_mangle)]
    fn _embassy_trace_poll_start(_executor_id: u32) {}

    #[unsafe(no_mangle)]
    fn _embassy_trace_task_end(_executor_id: u32, _task_id: u32) {}

    #[unsafe(no_mangle)]
    fn _embassy_trace_task_ready_begin(_executor_id: u32, _task_id: u32) {}

    #[unsafe(no_mangle)]
    fn _embassy_trace_executor_idle(_executor_id: u32) {}
}
