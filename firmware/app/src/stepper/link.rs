//! What the sequencer, the stepper task and the step timer share: the
//! request and event channels, and the prepared segments with the step
//! generator (behind a critical section: the step timer takes one event at
//! a time).

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, AtomicU8, AtomicU32, Ordering};

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;
use kinematics_core::stepper::{SegmentQueue, StepBlock, StepGenerator, StepTick};

use super::config::{DriverSignals, StepperConfig};

pub(super) mod messages;

pub use messages::{HomingFailure, MoveShape, StepperEvent, StepperRefusal, StepperRequest};

/// Prepared segments ahead of the step generator.
pub const STEP_QUEUE_LEN: usize = 8;

/// What a pressed limit switch does (the step timer checks before each
/// step event).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum LimitMode {
    /// Any pressed switch halts the steps: a fault.
    Guard,
    /// Homing seeks axis 0/1's switch: pressed, the steps halt (no fault).
    Seek(u8),
    /// Homing backs off a switch: not checked.
    Ignore,
}

/// The step timer's state: prepared segments and the generator.
struct StepCore {
    queue: SegmentQueue<STEP_QUEUE_LEN>,
    generator: StepGenerator,
}

/// The links of the stepper pan/tilt.
pub struct StepperLink {
    /// Sequencer → stepper task.
    pub requests: Channel<CriticalSectionRawMutex, StepperRequest, 4>,
    /// Stepper task → sequencer.
    pub events: Channel<CriticalSectionRawMutex, StepperEvent, 4>,
    /// New parameters (the latest wins), applied at rest.
    pub config: Signal<CriticalSectionRawMutex, StepperConfig>,
    core: Mutex<CriticalSectionRawMutex, RefCell<StepCore>>,
    /// Segments were prepared (wakes the step timer).
    pub(super) ready: Signal<CriticalSectionRawMutex, ()>,
    /// The step timer ran out of segments (wakes the stepper task).
    pub(super) drained: Signal<CriticalSectionRawMutex, ()>,
    /// Stop stepping now (stop button, fault): the step timer drops
    /// everything prepared at its next event.
    halt: AtomicBool,
    /// [`LimitMode`]: 0 guard, 1/2 seek pan/tilt, 3 ignore.
    limit_mode: AtomicU8,
    /// Switches pressed at the last step event (bit 0 pan, bit 1 tilt).
    pressed: AtomicU8,
    /// Switches that halted a move in guard mode (reported, then cleared).
    tripped: AtomicU8,
    /// The homing seek found its switch.
    seek_hit: AtomicBool,
    /// A new feed override, % (0: none pending; the latest wins).
    feed_percent: AtomicU8,
    /// Drivers energised (the stepper task decides, the step timer applies).
    pub(super) enabled: AtomicBool,
    /// A stepper task serves the link.
    attached: AtomicBool,
    /// STEP pulse width and DIR setup time, ns, ENABLE polarity (the
    /// stepper task sets them, the step timer applies them when it
    /// starts).
    pulse_ns: AtomicU32,
    dir_setup_ns: AtomicU32,
    enable_active_high: AtomicBool,
}

impl Default for StepperLink {
    fn default() -> Self {
        Self::new()
    }
}

impl StepperLink {
    /// Empty links (usable in a `static`).
    pub const fn new() -> Self {
        Self {
            requests: Channel::new(),
            events: Channel::new(),
            config: Signal::new(),
            core: Mutex::new(RefCell::new(StepCore {
                queue: SegmentQueue::new(),
                generator: StepGenerator::new(),
            })),
            ready: Signal::new(),
            drained: Signal::new(),
            halt: AtomicBool::new(false),
            limit_mode: AtomicU8::new(0),
            pressed: AtomicU8::new(0),
            tripped: AtomicU8::new(0),
            seek_hit: AtomicBool::new(false),
            feed_percent: AtomicU8::new(0),
            enabled: AtomicBool::new(false),
            attached: AtomicBool::new(false),
            pulse_ns: AtomicU32::new(0),
            dir_setup_ns: AtomicU32::new(0),
            enable_active_high: AtomicBool::new(false),
        }
    }

    /// Whether a stepper task serves the link (else `target stepper` is
    /// refused).
    pub fn is_attached(&self) -> bool {
        self.attached.load(Ordering::Relaxed)
    }

    pub(super) fn attach(&self) {
        self.attached.store(true, Ordering::Relaxed);
    }

    pub(super) fn set_signals(&self, signals: DriverSignals) {
        self.pulse_ns.store(signals.pulse_ns, Ordering::Relaxed);
        self.dir_setup_ns
            .store(signals.dir_setup_ns, Ordering::Relaxed);
        self.enable_active_high
            .store(signals.enable_active_high, Ordering::Relaxed);
    }

    pub(super) fn signals(&self) -> DriverSignals {
        DriverSignals {
            pulse_ns: self.pulse_ns.load(Ordering::Relaxed),
            dir_setup_ns: self.dir_setup_ns.load(Ordering::Relaxed),
            enable_active_high: self.enable_active_high.load(Ordering::Relaxed),
        }
    }

    /// Halts the steps at once (stop button, faults): nothing prepared
    /// runs any more; the stepper task forgets its plan and reports
    /// [`StepperEvent::Stopped`].
    pub fn halt(&self) {
        self.halt.store(true, Ordering::Release);
        self.ready.signal(());
        self.drained.signal(());
    }

    /// A new feed override, % (the sequencer's shell: the latest wins, no
    /// queue to overflow; the stepper task takes it within a refill
    /// period).
    pub fn set_feed_override(&self, percent: u8) {
        self.feed_percent.store(percent, Ordering::Relaxed);
    }

    /// The feed override set since the last call, % (the stepper task).
    pub(super) fn take_feed_override(&self) -> Option<u8> {
        Some(self.feed_percent.swap(0, Ordering::Relaxed)).filter(|&p| p > 0)
    }

    /// Takes a pending halt (the stepper task's side): drops everything
    /// prepared, under the step timer's lock, before clearing the flag, so
    /// nothing prepared before the halt can still run.
    pub(super) fn take_halt(&self) -> bool {
        if !self.halting() {
            return false;
        }
        self.core.lock(|core| {
            let mut core = core.borrow_mut();
            core.queue.clear();
            core.generator.halt();
        });
        self.halt.store(false, Ordering::Release);
        true
    }

    /// The step timer's limit check before a step event, with the
    /// switches `pressed` (`[pan, tilt]`): halts the steps when the mode
    /// says so; `false` when it did.
    pub fn limits_allow(&self, pressed: [bool; 2]) -> bool {
        let mask = u8::from(pressed[0]) | (u8::from(pressed[1]) << 1);
        self.pressed.store(mask, Ordering::Relaxed);
        let stop = match self.limit_mode.load(Ordering::Relaxed) {
            0 => {
                self.tripped.fetch_or(mask, Ordering::Relaxed);
                mask != 0
            }
            m @ 1..=2 => {
                let hit = mask & m != 0;
                self.seek_hit.fetch_or(hit, Ordering::Relaxed);
                hit
            }
            _ => false,
        };
        if stop {
            self.halt();
        }
        !stop
    }

    pub(super) fn set_limit_mode(&self, mode: LimitMode) {
        let code = match mode {
            LimitMode::Guard => 0,
            LimitMode::Seek(axis) => 1 + (axis & 1),
            LimitMode::Ignore => 3,
        };
        self.seek_hit.store(false, Ordering::Relaxed);
        self.limit_mode.store(code, Ordering::Relaxed);
    }

    /// Whether axis `axis`'s switch was pressed at the last step event.
    pub(super) fn is_pressed(&self, axis: usize) -> bool {
        self.pressed.load(Ordering::Relaxed) & (1 << axis) != 0
    }

    /// Switches that halted a move (cleared).
    pub(super) fn take_tripped(&self) -> u8 {
        self.tripped.swap(0, Ordering::Relaxed)
    }

    /// Whether the homing seek found its switch (cleared).
    pub(super) fn take_seek_hit(&self) -> bool {
        self.seek_hit.swap(false, Ordering::Relaxed)
    }

    /// Redefines the position of axis `axis` (homing, at rest).
    pub(super) fn set_position(&self, axis: usize, steps: i32) {
        self.core.lock(|core| {
            let mut core = core.borrow_mut();
            let mut position = core.generator.position_steps();
            if let Some(p) = position.get_mut(axis) {
                *p = steps;
            }
            core.generator.set_position(position);
        });
    }

    /// Whether a halt is pending.
    pub(super) fn halting(&self) -> bool {
        self.halt.load(Ordering::Acquire)
    }

    /// The step timer's work for one event: the next step of the prepared
    /// segments (`None`: nothing prepared, or halted). Integer adds and
    /// compares under a short critical section; no float, no division.
    pub fn step_tick(&self) -> Option<StepTick> {
        let halted = self.halting();
        self.core.lock(|core| {
            let mut core = core.borrow_mut();
            if halted {
                core.queue.clear();
                core.generator.halt();
                return None;
            }
            let StepCore { queue, generator } = &mut *core;
            generator.tick(queue)
        })
    }

    /// Runs `f` on the prepared segments (the stepper task fills them).
    pub(super) fn with_queue<R>(
        &self,
        f: impl FnOnce(&mut SegmentQueue<STEP_QUEUE_LEN>) -> R,
    ) -> R {
        self.core.lock(|core| f(&mut core.borrow_mut().queue))
    }

    /// Runs `f` on the prepared segments with the step generator's block
    /// in progress and running segment's period (a hold takes the
    /// prepared segments back and brakes from there), under the step
    /// timer's lock.
    pub(super) fn with_queue_executing<R>(
        &self,
        f: impl FnOnce(&mut SegmentQueue<STEP_QUEUE_LEN>, (StepBlock, Option<u32>)) -> R,
    ) -> R {
        self.core.lock(|core| {
            let StepCore { queue, generator } = &mut *core.borrow_mut();
            f(queue, generator.executing())
        })
    }

    /// Whether a step may come at the next event (prepared segments or
    /// one being run).
    pub fn has_steps(&self) -> bool {
        self.core.lock(|core| {
            let core = core.borrow();
            !core.queue.is_empty() || core.generator.is_running()
        })
    }

    /// Whether every prepared step has run.
    pub fn is_idle(&self) -> bool {
        self.core.lock(|core| {
            let core = core.borrow();
            core.queue.is_empty() && !core.generator.is_running()
        })
    }

    /// The running segment's speed over its block's cruise speed, ‰
    /// (0 at rest): M4 laser power follows it.
    pub fn speed_permille(&self) -> u16 {
        self.core
            .lock(|core| core.borrow().generator.speed_permille())
    }

    /// Position counted from the emitted steps, microsteps `[pan, tilt]`.
    pub fn position_steps(&self) -> [i32; 2] {
        self.core
            .lock(|core| core.borrow().generator.position_steps())
    }
}
