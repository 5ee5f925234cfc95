//! The simulator's embassy-time driver: a per-thread clock that is either
//! **virtual** (time jumps to the next timer whenever every task waits, so
//! runs are fast and deterministic) or **real-time** (the executor sleeps
//! until the next timer, for interactive use).
//!
//! The clock is thread-local, so independent simulations can run on
//! parallel test threads. Ticks are embassy-time's default 1 MHz (1 µs).

use std::cell::{Cell, RefCell};
use std::task::Waker;
use std::time::{Duration, Instant};

use embassy_time_driver::Driver;

struct ThreadClock {
    /// Current simulated time, µs since the simulation started.
    now_us: Cell<u64>,
    /// Pending timers: (deadline µs, waker).
    timers: RefCell<Vec<(u64, Waker)>>,
    /// Wall-clock origin in real-time mode.
    wall_origin: Cell<Option<Instant>>,
}

thread_local! {
    static CLOCK: ThreadClock = const {
        ThreadClock {
            now_us: Cell::new(0),
            timers: RefCell::new(Vec::new()),
            wall_origin: Cell::new(None),
        }
    };
}

/// Resets this thread's clock to t = 0 with no timers; `realtime` selects
/// wall-clock pacing.
pub fn reset(realtime: bool) {
    CLOCK.with(|c| {
        c.now_us.set(0);
        c.timers.borrow_mut().clear();
        c.wall_origin.set(realtime.then(Instant::now));
    });
}

/// Current simulated time, µs.
pub fn now_us() -> u64 {
    CLOCK.with(|c| c.now_us.get())
}

/// Earliest pending timer deadline, µs.
pub fn next_deadline_us() -> Option<u64> {
    CLOCK.with(|c| c.timers.borrow().iter().map(|(at, _)| *at).min())
}

/// Advances the clock to `t_us` (never backwards). In real-time mode this
/// sleeps until the wall clock reaches it.
pub fn advance_to(t_us: u64) {
    CLOCK.with(|c| {
        if let Some(origin) = c.wall_origin.get() {
            let target = origin + Duration::from_micros(t_us);
            let now = Instant::now();
            if target > now {
                std::thread::sleep(target - now);
            }
        }
        if t_us > c.now_us.get() {
            c.now_us.set(t_us);
        }
    });
}

/// Wakes every timer whose deadline has passed; returns how many fired.
pub fn fire_due() -> usize {
    let due: Vec<Waker> = CLOCK.with(|c| {
        let now = c.now_us.get();
        let mut timers = c.timers.borrow_mut();
        let mut due = Vec::new();
        timers.retain(|(at, waker)| {
            if *at <= now {
                due.push(waker.clone());
                false
            } else {
                true
            }
        });
        due
    });
    let fired = due.len();
    for waker in due {
        waker.wake();
    }
    fired
}

struct SimDriver;

impl Driver for SimDriver {
    fn now(&self) -> u64 {
        now_us()
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        CLOCK.with(|c| {
            let mut timers = c.timers.borrow_mut();
            if let Some(entry) = timers.iter_mut().find(|(_, w)| w.will_wake(waker)) {
                entry.0 = entry.0.min(at);
            } else {
                timers.push((at, waker.clone()));
            }
        });
    }
}

embassy_time_driver::time_driver_impl!(static DRIVER: SimDriver = SimDriver);

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::task::Wake;

    struct Counter(AtomicUsize);
    impl Wake for Counter {
        fn wake(self: Arc<Self>) {
            self.0.fetch_add(1, Ordering::SeqCst);
        }
    }

    #[test]
    fn timers_fire_in_virtual_time_only_when_due() {
        reset(false);
        let counter = Arc::new(Counter(AtomicUsize::new(0)));
        let waker = Waker::from(counter.clone());
        SimDriver.schedule_wake(5_000, &waker);
        assert_eq!(next_deadline_us(), Some(5_000));
        assert_eq!(fire_due(), 0);
        advance_to(4_999);
        assert_eq!(fire_due(), 0);
        advance_to(5_000);
        assert_eq!(fire_due(), 1);
        assert_eq!(counter.0.load(Ordering::SeqCst), 1);
        assert_eq!(next_deadline_us(), None);
        // Time never runs backwards.
        advance_to(10);
        assert_eq!(now_us(), 5_000);
    }

    #[test]
    fn rescheduling_the_same_waker_keeps_the_earliest_deadline() {
        reset(false);
        let counter = Arc::new(Counter(AtomicUsize::new(0)));
        let waker = Waker::from(counter);
        SimDriver.schedule_wake(900, &waker);
        SimDriver.schedule_wake(300, &waker);
        SimDriver.schedule_wake(600, &waker);
        assert_eq!(next_deadline_us(), Some(300));
    }
}
