//! Runs embassy tasks on the host on one thread, driving the simulated
//! clock: poll until every task waits, then jump (or, in real-time mode,
//! sleep) to the next timer.

use std::cell::Cell;
use std::future::Future;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use embassy_executor::Spawner;
use embassy_executor::raw::{Executor, TaskStorage};

use crate::clock;

/// The pender embassy-executor calls when a task is woken: `context` is the
/// run's "work pending" flag.
#[unsafe(export_name = "__pender")]
fn pender(context: *mut ()) {
    // SAFETY: every executor in this crate is created with a pointer to a
    // leaked `AtomicBool` as its context (see `run`).
    let flag = unsafe { &*(context as *const AtomicBool) };
    flag.store(true, Ordering::SeqCst);
}

/// Spawns a future as an embassy task (storage is leaked: one per task per
/// simulation run, a few hundred bytes).
pub fn spawn<F: Future + 'static>(spawner: &Spawner, future: F) {
    let storage: &'static TaskStorage<F> = Box::leak(Box::new(TaskStorage::new()));
    match storage.spawn(move || future) {
        Ok(token) => spawner.spawn(token),
        Err(e) => panic!("spawning a fresh task storage cannot fail: {e:?}"),
    }
}

/// Why a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunEnd {
    /// `stop` returned true.
    Stopped,
    /// Simulated time reached the limit.
    TimeLimit,
    /// Every task waits and no timer is pending: nothing can happen again.
    Quiescent,
    /// Tasks kept waking each other without letting time pass (a busy
    /// loop in a task body: on the target it would starve the CPU).
    Livelock,
}

thread_local! {
    /// Longest host CPU time one executor poll took in this thread's last
    /// run.
    static LONGEST_POLL: Cell<Duration> = const { Cell::new(Duration::ZERO) };
}

/// Host CPU time of the longest single executor poll of the last run on
/// this thread: how long one step of the task bodies held the executor,
/// every other task waiting. Virtual time stands still during a poll, so
/// this is the measure of the work done in one step. It is the thread's
/// CPU time (time the OS gave other processes is not counted) where the
/// platform has it, else wall-clock time.
pub fn longest_poll() -> Duration {
    LONGEST_POLL.with(Cell::get)
}

/// This thread's CPU time.
#[cfg(unix)]
fn cpu_time() -> Duration {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the call only writes it.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return Duration::ZERO;
    }
    Duration::new(
        u64::try_from(ts.tv_sec).unwrap_or(0),
        u32::try_from(ts.tv_nsec).unwrap_or(0),
    )
}

/// Wall-clock time since the first call (no thread CPU clock here).
#[cfg(not(unix))]
fn cpu_time() -> Duration {
    static ORIGIN: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
    ORIGIN.get_or_init(std::time::Instant::now).elapsed()
}

/// Polls at one instant after which a run counts as livelocked.
pub const MAX_POLLS_PER_INSTANT: u32 = 1_000_000;

/// Runs tasks spawned by `init` until `stop()` is true (checked whenever
/// the tasks are idle), time passes `limit_us`, or nothing can happen.
pub fn run(
    realtime: bool,
    limit_us: u64,
    init: impl FnOnce(Spawner),
    mut stop: impl FnMut() -> bool,
) -> RunEnd {
    clock::reset(realtime);
    LONGEST_POLL.with(|l| l.set(Duration::ZERO));
    let pending: &'static AtomicBool = Box::leak(Box::new(AtomicBool::new(true)));
    let executor: &'static Executor = Box::leak(Box::new(Executor::new(
        pending as *const AtomicBool as *mut (),
    )));
    init(executor.spawner());
    loop {
        let mut polls = 0u32;
        loop {
            while pending.swap(false, Ordering::SeqCst) {
                polls += 1;
                if polls > MAX_POLLS_PER_INSTANT {
                    return RunEnd::Livelock;
                }
                let started = cpu_time();
                // SAFETY: poll is only ever called from this loop, never
                // re-entrantly (the pender only sets a flag).
                unsafe { executor.poll() };
                let took = cpu_time().saturating_sub(started);
                LONGEST_POLL.with(|l| l.set(l.get().max(took)));
            }
            if clock::fire_due() == 0 && !pending.load(Ordering::SeqCst) {
                break;
            }
        }
        if stop() {
            return RunEnd::Stopped;
        }
        let Some(next) = clock::next_deadline_us() else {
            return RunEnd::Quiescent;
        };
        if next > limit_us {
            clock::advance_to(limit_us);
            return RunEnd::TimeLimit;
        }
        clock::advance_to(next);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embassy_time::{Duration, Instant, Timer};
    use std::cell::RefCell;
    use std::rc::Rc;

    #[test]
    fn virtual_time_jumps_over_sleeps() {
        let log: Rc<RefCell<Vec<(u64, &str)>>> = Rc::default();
        let wall = std::time::Instant::now();
        let (a, b) = (log.clone(), log.clone());
        let end = run(
            false,
            60_000_000,
            |spawner| {
                spawn(&spawner, async move {
                    Timer::after(Duration::from_secs(10)).await;
                    a.borrow_mut().push((Instant::now().as_micros(), "a"));
                });
                spawn(&spawner, async move {
                    Timer::after(Duration::from_millis(1500)).await;
                    b.borrow_mut().push((Instant::now().as_micros(), "b"));
                });
            },
            || false,
        );
        assert_eq!(end, RunEnd::Quiescent);
        assert_eq!(*log.borrow(), vec![(1_500_000, "b"), (10_000_000, "a")]);
        assert!(wall.elapsed() < std::time::Duration::from_secs(2));
    }

    #[test]
    fn a_busy_loop_is_reported_not_run_forever() {
        let end = run(
            false,
            2_000_000,
            |spawner| {
                spawn(&spawner, async {
                    loop {
                        embassy_futures::yield_now().await;
                    }
                });
            },
            || false,
        );
        assert_eq!(end, RunEnd::Livelock);
        assert_eq!(clock::now_us(), 0);
    }

    #[test]
    fn time_limit_ends_a_run_that_never_stops() {
        let end = run(
            false,
            2_000_000,
            |spawner| {
                spawn(&spawner, async {
                    loop {
                        Timer::after_millis(100).await;
                    }
                });
            },
            || false,
        );
        assert_eq!(end, RunEnd::TimeLimit);
        assert_eq!(clock::now_us(), 2_000_000);
    }
}
