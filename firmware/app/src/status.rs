//! The status board: a snapshot of what the firmware is doing, published
//! by the sequencer (a view of its core's state) and read by the LEDs,
//! the watchdog and the simulator.

use core::cell::RefCell;

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;

use crate::domain::{Aim, Pattern, Target};

/// What the sequencer is doing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Activity {
    /// Nothing; laser off.
    Idle,
    /// Running a pattern.
    Pattern(Pattern),
    /// Holding a goto/grid target.
    Goto,
    /// Running (or holding) queued G-code motion.
    Gcode,
    /// The stepper homes (`home`, `$H`); laser off.
    Homing,
}

/// Where the current point is in its cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Phase {
    /// The servos are travelling to the first point of a pass of a
    /// pattern, or to a goto target: off the figure, laser dark in every
    /// mode.
    Approaching,
    /// The servos are travelling from one point of the figure to the next.
    Moving,
    /// Arrived; dwelling on the point.
    Dwelling,
    /// Arrived at a goto target; holding until the next command.
    Holding,
}

impl Phase {
    /// Whether the servos are travelling (no arrival confirmed yet).
    pub fn is_travel(self) -> bool {
        matches!(self, Phase::Approaching | Phase::Moving)
    }
}

/// A copy of the firmware state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Snapshot {
    /// Current activity.
    pub activity: Activity,
    /// Phase of the current point.
    pub phase: Option<Phase>,
    /// Index of the current point within the pass.
    pub point_index: Option<usize>,
    /// Completed passes of the pattern.
    pub pass: u32,
    /// Last target and its aim.
    pub target: Option<(Target, Aim)>,
    /// Laser output.
    pub laser_on: bool,
    /// Servo currently faulty.
    pub faulty_servo: Option<u8>,
    /// Incremented by the sequencer's housekeeping tick (liveness).
    pub heartbeat: u32,
}

impl Snapshot {
    const INITIAL: Snapshot = Snapshot {
        activity: Activity::Idle,
        phase: None,
        point_index: None,
        pass: 0,
        target: None,
        laser_on: false,
        faulty_servo: None,
        heartbeat: 0,
    };
}

/// Shared, lock-protected [`Snapshot`].
pub struct StatusBoard {
    inner: Mutex<CriticalSectionRawMutex, RefCell<Snapshot>>,
}

impl StatusBoard {
    /// Initial state: idle, laser off.
    pub const fn new() -> Self {
        Self {
            inner: Mutex::new(RefCell::new(Snapshot::INITIAL)),
        }
    }

    /// A copy of the current state.
    pub fn snapshot(&self) -> Snapshot {
        self.inner.lock(|s| *s.borrow())
    }

    /// Replaces the state (the sequencer publishes its status view).
    pub fn publish(&self, snapshot: Snapshot) {
        self.inner.lock(|s| *s.borrow_mut() = snapshot);
    }

    /// Changes the state.
    pub fn update(&self, f: impl FnOnce(&mut Snapshot)) {
        self.inner.lock(|s| f(&mut s.borrow_mut()));
    }
}

impl Default for StatusBoard {
    fn default() -> Self {
        Self::new()
    }
}
