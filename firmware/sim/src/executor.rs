//! Runs embassy tasks on the host on one thread, driving the simulated
//! clock: poll until every task waits, then jump (or, in real-time mode,
//! sleep) to the next timer.
//!
//! Every poll of every task is accounted ([`task_steps`]): the thread CPU
//! time it took (`CLOCK_THREAD_CPUTIME_ID`, so other processes on a loaded
//! machine do not inflate it), the longest poll per task and each poll
//! longer than [`LONG_STEP_NS`]. In virtual time a poll takes no simulated
//! time, so this is the only measure of how long a task step holds the
//! executor.
//!
//! What it models and what it does not: a task step on the target runs the
//! same code (the task bodies of `laser-app`) to the same `await`, so a
//! step that is long here is long there. The host's CPU time is a **lower
//! bound** of the Cortex-M4F's (a faster CPU with hardware `f64`; the
//! tests' dev profile is less optimised than the release firmware but far
//! from the M4F's soft-float `f64`, 30–60× slower than the host), so a step
//! under 1 ms here is not proven under 1 ms on the target; issue 11's M4
//! cost model scales it. Interrupts, DMA and flash wait states are not
//! modelled; time a task spends awaiting is not a step. The simulator's own
//! work inside a firmware task's poll (simulated peripherals and their
//! recording) is left out ([`simulator_work`]).

use std::cell::RefCell;
use std::future::Future;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, Ordering};
use std::task::{Context, Poll};

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
/// simulation run, a few hundred bytes). Its steps are accounted as a
/// simulator task named `"task"`; see [`spawn_task`].
pub fn spawn<F: Future + 'static>(spawner: &Spawner, future: F) {
    spawn_task(spawner, "task", TaskKind::Simulator, future);
}

/// Spawns a future as an embassy task named `name`, accounting the CPU
/// time of each of its polls ([`task_steps`]).
pub fn spawn_task<F: Future + 'static>(
    spawner: &Spawner,
    name: &'static str,
    kind: TaskKind,
    future: F,
) {
    let index = STEPS.with(|s| {
        let mut steps = s.borrow_mut();
        steps.push(TaskSteps::new(name, kind));
        steps.len() - 1
    });
    let accounted = Accounted {
        index,
        inner: Box::pin(future),
    };
    let storage: &'static TaskStorage<Accounted<F>> = Box::leak(Box::new(TaskStorage::new()));
    match storage.spawn(move || accounted) {
        Ok(token) => spawner.spawn(token),
        Err(e) => panic!("spawning a fresh task storage cannot fail: {e:?}"),
    }
}

/// Whose code a task runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TaskKind {
    /// A firmware task body (runs on the target too).
    Firmware,
    /// Simulator machinery (host, sampler, …): not on the target.
    Simulator,
}

/// Polls longer than this are listed one by one in [`TaskSteps`], ns
/// (1 ms: the longest step a task may hold the executor for).
pub const LONG_STEP_NS: u64 = 1_000_000;

/// Long polls listed per task at most (the count goes on).
const LONG_STEPS_KEPT: usize = 1000;

/// CPU-time accounting of one task's steps (polls) during a run.
#[derive(Debug, Clone, PartialEq)]
pub struct TaskSteps {
    /// Task name.
    pub name: &'static str,
    /// Firmware task body or simulator machinery.
    pub kind: TaskKind,
    /// Polls.
    pub polls: u64,
    /// Thread CPU time of all polls, ns.
    pub total_cpu_ns: u64,
    /// Longest poll, ns of thread CPU time.
    pub max_cpu_ns: u64,
    /// Simulated time of the longest poll, µs.
    pub max_at_us: u64,
    /// Polls longer than [`LONG_STEP_NS`]: (simulated time µs, CPU ns), the
    /// first 1000.
    pub long_steps: Vec<(u64, u64)>,
    /// Polls longer than [`LONG_STEP_NS`], all of them.
    pub long_step_count: u64,
}

impl TaskSteps {
    fn new(name: &'static str, kind: TaskKind) -> Self {
        Self {
            name,
            kind,
            polls: 0,
            total_cpu_ns: 0,
            max_cpu_ns: 0,
            max_at_us: 0,
            long_steps: Vec::new(),
            long_step_count: 0,
        }
    }

    fn account(&mut self, cpu_ns: u64) {
        let t_us = clock::now_us();
        self.polls += 1;
        self.total_cpu_ns = self.total_cpu_ns.saturating_add(cpu_ns);
        if cpu_ns > self.max_cpu_ns {
            self.max_cpu_ns = cpu_ns;
            self.max_at_us = t_us;
        }
        if cpu_ns > LONG_STEP_NS {
            self.long_step_count += 1;
            if self.long_steps.len() < LONG_STEPS_KEPT {
                self.long_steps.push((t_us, cpu_ns));
            }
        }
    }
}

thread_local! {
    /// Step accounting of the tasks spawned on this thread since the last
    /// [`run`] started.
    static STEPS: RefCell<Vec<TaskSteps>> = const { RefCell::new(Vec::new()) };
    /// CPU time spent in [`simulator_work`] on this thread, ns.
    static SIMULATOR_NS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Runs `work`, the simulator's own bookkeeping inside a firmware task's
/// poll (simulated peripherals: the servo bus and its recording, the DAC's
/// recording, the laser recorder), and leaves its CPU time out of the
/// task's step: the target does not do it.
pub fn simulator_work<R>(work: impl FnOnce() -> R) -> R {
    let start = thread_cpu_ns();
    let result = work();
    let spent = thread_cpu_ns().saturating_sub(start);
    SIMULATOR_NS.with(|s| s.set(s.get().saturating_add(spent)));
    result
}

/// Step accounting of every task of this thread's last (or current) run,
/// in spawn order.
pub fn task_steps() -> Vec<TaskSteps> {
    STEPS.with(|s| s.borrow().clone())
}

/// The longest step (poll) of any firmware task in this thread's last (or
/// current) run, in thread CPU time.
pub fn longest_poll() -> std::time::Duration {
    let ns = STEPS.with(|s| {
        s.borrow()
            .iter()
            .filter(|t| t.kind == TaskKind::Firmware)
            .map(|t| t.max_cpu_ns)
            .max()
            .unwrap_or(0)
    });
    std::time::Duration::from_nanos(ns)
}

/// The longest firmware task step of `steps` (a run's accounting), in
/// thread CPU time.
pub fn longest_firmware_step(steps: &[TaskSteps]) -> std::time::Duration {
    let ns = steps
        .iter()
        .filter(|t| t.kind == TaskKind::Firmware)
        .map(|t| t.max_cpu_ns)
        .max()
        .unwrap_or(0);
    std::time::Duration::from_nanos(ns)
}

/// The step accounting of several runs of the same simulation with the
/// host's noise taken out: only the long steps that recur in **every**
/// run. A simulation is deterministic in virtual time, so a step is the
/// same work in every run and is identified by its task (spawn order) and
/// simulated instant; its cost is the least CPU time any run measured.
/// Host load (other processes, a sibling hyper-thread, the hypervisor)
/// inflates a poll's CPU time now and then, never the same poll in every
/// run; work that really takes too long shows in each. A poll that was
/// short in one run counts as short: its longest, `max_cpu_ns`, is then
/// the least of the runs' longest, capped at [`LONG_STEP_NS`].
///
/// `runs` must be runs of one simulation (same tasks in the same order);
/// the counts of polls come from the first.
pub fn recurring_steps(runs: &[Vec<TaskSteps>]) -> Vec<TaskSteps> {
    let Some((first, others)) = runs.split_first() else {
        return Vec::new();
    };
    first
        .iter()
        .enumerate()
        .map(|(i, task)| {
            let same: Vec<&TaskSteps> = others
                .iter()
                .filter_map(|run| run.get(i))
                .filter(|t| t.name == task.name)
                .collect();
            let long_steps: Vec<(u64, u64)> = task
                .long_steps
                .iter()
                .filter_map(|&(t_us, cpu_ns)| {
                    same.iter()
                        .try_fold(cpu_ns, |least, other| {
                            let again = other.long_steps.iter().find(|s| s.0 == t_us)?;
                            Some(least.min(again.1))
                        })
                        .map(|least| (t_us, least))
                })
                .collect();
            let recurring_max = long_steps.iter().max_by_key(|s| s.1).copied();
            let least_max = same
                .iter()
                .map(|t| t.max_cpu_ns)
                .fold(task.max_cpu_ns, u64::min)
                .min(LONG_STEP_NS);
            let (max_cpu_ns, max_at_us) = match recurring_max {
                Some((t_us, cpu_ns)) => (cpu_ns, t_us),
                None => (least_max, task.max_at_us),
            };
            TaskSteps {
                long_step_count: long_steps.len() as u64,
                long_steps,
                max_cpu_ns,
                max_at_us,
                ..task.clone()
            }
        })
        .collect()
}

/// CPU time this thread has used, ns.
#[cfg(unix)]
fn thread_cpu_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a
    // constant every Unix this builds on supports.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return 0;
    }
    (ts.tv_sec as u64)
        .saturating_mul(1_000_000_000)
        .saturating_add(ts.tv_nsec as u64)
}

/// Without a thread CPU clock: wall time since first use (an upper bound
/// on a loaded machine), ns.
#[cfg(not(unix))]
fn thread_cpu_ns() -> u64 {
    use std::sync::OnceLock;
    static ORIGIN: OnceLock<std::time::Instant> = OnceLock::new();
    ORIGIN
        .get_or_init(std::time::Instant::now)
        .elapsed()
        .as_nanos() as u64
}

/// A task's future with its polls accounted.
struct Accounted<F> {
    index: usize,
    inner: Pin<Box<F>>,
}

impl<F: Future> Future for Accounted<F> {
    type Output = F::Output;

    fn poll(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<F::Output> {
        let simulator_before = SIMULATOR_NS.with(|s| s.get());
        let start = thread_cpu_ns();
        let result = self.inner.as_mut().poll(cx);
        let elapsed = thread_cpu_ns().saturating_sub(start);
        let simulator_ns = SIMULATOR_NS
            .with(|s| s.get())
            .saturating_sub(simulator_before);
        let cpu_ns = elapsed.saturating_sub(simulator_ns);
        let index = self.index;
        STEPS.with(|s| {
            if let Some(steps) = s.borrow_mut().get_mut(index) {
                steps.account(cpu_ns);
            }
        });
        result
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
    STEPS.with(|s| s.borrow_mut().clear());
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
                // SAFETY: poll is only ever called from this loop, never
                // re-entrantly (the pender only sets a flag).
                unsafe { executor.poll() };
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
mod tests;
