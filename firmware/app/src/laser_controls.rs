//! The laser controls of a Class 3B/4 product (IEC 60825-1, 21 CFR
//! 1040.10): a remote interlock input, a key switch input, an emission
//! indicator output and the manual reset (`arm`). See
//! `docs/laser-safety.md` for the wiring and the behaviour.
//!
//! * [`logic`]: the pure state machine (debounce, latch, the indicator's
//!   lead time before emission becomes possible).
//! * [`ControlsLink`]: what the laser-controls task (`app`) shares with the
//!   sequencer: the controls' state for `status` and `?`, and the `arm`
//!   requests. The task forbids and permits the master
//!   [`LaserGate`](crate::laser_gate::LaserGate): no laser output can be
//!   on unless the controls are armed.
//!
//! A board without the controls (the simulator unless asked for them)
//! never publishes a state: [`ControlsLink::view`] is `None` and the gate
//! stays permitted.

pub mod logic;

use core::sync::atomic::{AtomicU8, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;

pub use self::logic::{ArmRefusal, Arming, ControlInputs, ControlsLogic, LatchCause, SETTLE_US};

/// The controls' state without times, as `status` and `?` show it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ControlsState {
    /// Emission latched off; `arm` needed.
    Latched(LatchCause),
    /// The emission indicator is on; emission possible after the delay.
    Arming,
    /// Emission possible.
    Armed,
}

/// What the controls read and where they are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ControlsView {
    /// The debounced inputs.
    pub inputs: ControlInputs,
    /// The latch and arming state.
    pub state: ControlsState,
}

impl ControlsView {
    /// The view of `logic`.
    pub fn of(logic: &ControlsLogic) -> Self {
        Self {
            inputs: logic.inputs(),
            state: match logic.arming() {
                Arming::Latched(cause) => ControlsState::Latched(cause),
                Arming::Arming { .. } => ControlsState::Arming,
                Arming::Armed => ControlsState::Armed,
            },
        }
    }

    /// Why `arm` would be refused now, if it would.
    pub fn arm_refusal(&self) -> Option<ArmRefusal> {
        if !self.inputs.interlock_closed {
            Some(ArmRefusal::InterlockOpen)
        } else if !self.inputs.key_on {
            Some(ArmRefusal::KeyOff)
        } else {
            None
        }
    }

    /// grbl 1.1's safety-door substate for `?` when emission is not
    /// possible: `1` (stopped, "door" still open: the interlock open or
    /// the key off), `0` (closed, waiting for the reset: `arm`), `3`
    /// (closed, resuming: the indicator's delay runs); `None` when armed.
    pub fn door_substate(&self) -> Option<u8> {
        match self.state {
            ControlsState::Armed => None,
            ControlsState::Arming => Some(3),
            ControlsState::Latched(_) if self.arm_refusal().is_some() => Some(1),
            ControlsState::Latched(_) => Some(0),
        }
    }

    fn pack(self) -> u8 {
        let state = match self.state {
            ControlsState::Latched(LatchCause::PowerUp) => 0,
            ControlsState::Latched(LatchCause::InterlockOpened) => 1,
            ControlsState::Latched(LatchCause::KeyOff) => 2,
            ControlsState::Arming => 3,
            ControlsState::Armed => 4,
        };
        FITTED
            | u8::from(self.inputs.interlock_closed) << 1
            | u8::from(self.inputs.key_on) << 2
            | state << 3
    }

    fn unpack(bits: u8) -> Option<Self> {
        if bits & FITTED == 0 {
            return None;
        }
        let state = match bits >> 3 {
            0 => ControlsState::Latched(LatchCause::PowerUp),
            1 => ControlsState::Latched(LatchCause::InterlockOpened),
            2 => ControlsState::Latched(LatchCause::KeyOff),
            3 => ControlsState::Arming,
            _ => ControlsState::Armed,
        };
        Some(Self {
            inputs: ControlInputs {
                interlock_closed: bits & 2 != 0,
                key_on: bits & 4 != 0,
            },
            state,
        })
    }
}

/// Bit set in a packed view: the board has the controls.
const FITTED: u8 = 1;

/// The laser-controls task ↔ sequencer link. Starts "not fitted".
pub struct ControlsLink {
    /// The packed [`ControlsView`] (0: no controls on this board).
    view: AtomicU8,
    /// `arm` requests: the emission indicator's delay to arm with, ms.
    pub arm: Signal<CriticalSectionRawMutex, u32>,
}

impl ControlsLink {
    /// A link with no controls behind it yet.
    pub const fn new() -> Self {
        Self {
            view: AtomicU8::new(0),
            arm: Signal::new(),
        }
    }

    /// The controls' state; `None` on a board without them.
    pub fn view(&self) -> Option<ControlsView> {
        ControlsView::unpack(self.view.load(Ordering::Acquire))
    }

    /// Publishes the controls' state (the laser-controls task).
    pub fn publish(&self, view: ControlsView) {
        self.view.store(view.pack(), Ordering::Release);
    }
}

impl Default for ControlsLink {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_pack_and_unpack_and_an_unfitted_link_has_none() {
        let link = ControlsLink::new();
        assert_eq!(link.view(), None);
        for state in [
            ControlsState::Latched(LatchCause::PowerUp),
            ControlsState::Latched(LatchCause::InterlockOpened),
            ControlsState::Latched(LatchCause::KeyOff),
            ControlsState::Arming,
            ControlsState::Armed,
        ] {
            for (interlock_closed, key_on) in
                [(false, false), (true, false), (false, true), (true, true)]
            {
                let view = ControlsView {
                    inputs: ControlInputs {
                        interlock_closed,
                        key_on,
                    },
                    state,
                };
                link.publish(view);
                assert_eq!(link.view(), Some(view));
            }
        }
    }

    #[test]
    fn door_substates_follow_grbl() {
        let view = |closed, state| ControlsView {
            inputs: ControlInputs {
                interlock_closed: closed,
                key_on: true,
            },
            state,
        };
        let latched = ControlsState::Latched(LatchCause::InterlockOpened);
        assert_eq!(view(false, latched).door_substate(), Some(1));
        assert_eq!(view(true, latched).door_substate(), Some(0));
        assert_eq!(view(true, ControlsState::Arming).door_substate(), Some(3));
        assert_eq!(view(true, ControlsState::Armed).door_substate(), None);
    }
}
