//! The master laser gate: one switch that no sample stream and no laser
//! command can override (SPEC §9: the laser is off unless a pattern is
//! deliberately drawing).
//!
//! The laser that actually shines is the *effective* laser:
//!
//! ```text
//! effective = requested AND gate open AND (for streamed samples)
//!             the samples were computed under the gate's current generation
//! ```
//!
//! * [`LaserGate::close`] turns the laser off at once and starts a new
//!   *generation*. The sequencer closes it synchronously whenever it
//!   processes `stop`, a fault, the stop button or a new run; the galvo
//!   loop closes it on an underrun. On the target the close hook clears
//!   the laser-enable pin straight away, from whatever context closed it.
//! * Samples already handed to the DAC carry the generation they were
//!   computed under; after a close they can no longer light the laser,
//!   even once the gate is open again for a new run (the target stops the
//!   laser stream; the simulator records them dark).
//! * [`LaserGate::open`] takes the generation the opener saw when its run
//!   started: it opens only if nobody closed the gate since, so a stale
//!   opener (a run already stopped) cannot relight it.
//!
//! * [`LaserGate::forbid`] (the laser controls: interlock open, key off,
//!   not armed) closes the gate and refuses every [`LaserGate::open`]
//!   until [`LaserGate::permit`]: the controls' AND on every laser output.
//!   A gate starts permitted (a board without the controls).
//!
//! Use one `static` gate shared by the sequencer (gimbal laser pin), the
//! galvo loop (sample stream) and the board (the pin itself).

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

/// The gate's state: whether it is open and its generation (the number of
/// closes since boot, wrapping).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GateState {
    /// Closes since boot (wrapping): samples computed under an older
    /// generation stay dark.
    pub generation: u32,
    /// Whether the laser may be lit.
    pub open: bool,
}

impl GateState {
    fn pack(self) -> u32 {
        (self.generation << 1) | u32::from(self.open)
    }

    fn unpack(bits: u32) -> Self {
        Self {
            generation: bits >> 1,
            open: bits & 1 == 1,
        }
    }

    /// Whether a laser request made under `generation` shines in this
    /// state.
    pub fn passes(self, lit: bool, generation: u32) -> bool {
        lit && self.open && self.generation == generation
    }
}

/// The master laser gate (see the module docs). Starts closed at
/// generation 0.
pub struct LaserGate {
    /// [`GateState`] packed: generation << 1 | open. Generations count
    /// modulo 2³¹.
    state: AtomicU32,
    /// The laser controls permit emission (see [`LaserGate::forbid`]).
    permitted: AtomicBool,
    /// Called with the new state after every change (a close always is
    /// one): on the target it clears the laser pin when the gate closes,
    /// in the simulator it records the change with its time.
    on_change: fn(GateState),
}

fn no_hook(_: GateState) {}

impl LaserGate {
    /// A closed gate without a hook (tests, hosts without a laser pin).
    pub const fn new() -> Self {
        Self::with_hook(no_hook)
    }

    /// A closed gate that calls `on_change` with the new state after
    /// every change. The hook runs in the context that changed the gate
    /// (a task, or an interrupt on the target): keep it short.
    pub const fn with_hook(on_change: fn(GateState)) -> Self {
        Self {
            state: AtomicU32::new(0),
            permitted: AtomicBool::new(true),
            on_change,
        }
    }

    /// The current state.
    pub fn state(&self) -> GateState {
        GateState::unpack(self.state.load(Ordering::Acquire))
    }

    /// The current generation.
    pub fn generation(&self) -> u32 {
        self.state().generation
    }

    /// Whether the gate is open.
    pub fn is_open(&self) -> bool {
        self.state().open
    }

    /// Whether a laser request made under `generation` shines now.
    pub fn passes(&self, lit: bool, generation: u32) -> bool {
        self.state().passes(lit, generation)
    }

    /// Closes the gate at once and starts a new generation, which it
    /// returns: everything requested under earlier generations stays dark
    /// for good.
    pub fn close(&self) -> u32 {
        self.close_into(|generation| (generation + 1) & (u32::MAX >> 1))
    }

    /// Closes the gate at once without ending the generation: the laser
    /// goes dark now (samples already handed to the DAC included), but the
    /// run goes on and may [`open`](Self::open) it again under the same
    /// generation (`laser off` mid-run: the mirrors still draw, dark, and
    /// `laser auto` lights them again). Returns the generation.
    pub fn shut(&self) -> u32 {
        self.close_into(|generation| generation)
    }

    /// Closes the gate atomically, its generation becoming
    /// `next_generation` of the current one; reports the change and
    /// returns the new generation.
    fn close_into(&self, next_generation: impl Fn(u32) -> u32) -> u32 {
        let mut current = self.state.load(Ordering::Acquire);
        loop {
            let next = GateState {
                generation: next_generation(GateState::unpack(current).generation),
                open: false,
            };
            match self.state.compare_exchange_weak(
                current,
                next.pack(),
                Ordering::AcqRel,
                Ordering::Acquire,
            ) {
                Ok(_) => {
                    (self.on_change)(next);
                    return next.generation;
                }
                Err(seen) => current = seen,
            }
        }
    }

    /// Closes the gate for good (a new generation, as [`Self::close`])
    /// and refuses every [`Self::open`] until [`Self::permit`]: the laser
    /// controls latched emission off. Returns the new generation.
    pub fn forbid(&self) -> u32 {
        // First the flag, then the close: an opener that saw the flag
        // still set opens under the old generation, which the close ends.
        self.permitted.store(false, Ordering::SeqCst);
        self.close()
    }

    /// Lets runs open the gate again (the laser controls are armed). Opens
    /// nothing by itself: runs stopped by [`Self::forbid`] stay dark.
    pub fn permit(&self) {
        self.permitted.store(true, Ordering::SeqCst);
    }

    /// Whether the laser controls permit emission.
    pub fn is_permitted(&self) -> bool {
        self.permitted.load(Ordering::SeqCst)
    }

    /// Opens the gate for a run that started under `generation`; refused
    /// (`false`, gate unchanged) when it was closed since or the laser
    /// controls forbid emission. `true` when the gate is open for
    /// `generation` afterwards.
    pub fn open(&self, generation: u32) -> bool {
        if !self.is_permitted() {
            return false;
        }
        let closed = GateState {
            generation,
            open: false,
        };
        let opened = GateState {
            generation,
            open: true,
        };
        match self.state.compare_exchange(
            closed.pack(),
            opened.pack(),
            Ordering::AcqRel,
            Ordering::Acquire,
        ) {
            Ok(_) => {
                (self.on_change)(opened);
                true
            }
            Err(seen) => seen == opened.pack(),
        }
    }
}

impl Default for LaserGate {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::sync::atomic::AtomicUsize;

    #[test]
    fn starts_closed_and_opens_only_for_the_current_generation() {
        let gate = LaserGate::new();
        assert!(!gate.is_open());
        assert!(!gate.passes(true, 0));
        assert!(gate.open(0));
        assert!(gate.passes(true, 0));
        assert!(!gate.passes(false, 0), "the gate never lights by itself");
        assert!(gate.open(0), "opening an open gate again is fine");
        let g1 = gate.close();
        assert_eq!(g1, 1);
        assert!(!gate.is_open());
        assert!(!gate.open(0), "a stale run cannot reopen it");
        assert!(!gate.is_open());
        assert!(gate.open(g1));
        assert!(
            !gate.passes(true, 0),
            "samples of an old generation stay dark"
        );
        assert!(gate.passes(true, g1));
    }

    #[test]
    fn every_close_is_a_new_generation_and_reported() {
        static CHANGES: AtomicUsize = AtomicUsize::new(0);
        static LAST: AtomicU32 = AtomicU32::new(u32::MAX);
        fn hook(state: GateState) {
            CHANGES.fetch_add(1, Ordering::Relaxed);
            LAST.store(state.pack(), Ordering::Relaxed);
        }
        let gate = LaserGate::with_hook(hook);
        let a = gate.close();
        let b = gate.close();
        assert_ne!(a, b, "closing a closed gate still ends the generation");
        assert_eq!(CHANGES.load(Ordering::Relaxed), 2);
        assert!(gate.open(b));
        assert_eq!(CHANGES.load(Ordering::Relaxed), 3);
        assert_eq!(
            GateState::unpack(LAST.load(Ordering::Relaxed)),
            GateState {
                generation: b,
                open: true
            }
        );
        // A refused open changes nothing and reports nothing.
        assert!(!gate.open(a));
        assert_eq!(CHANGES.load(Ordering::Relaxed), 3);
    }

    #[test]
    fn shutting_darkens_now_and_the_same_run_may_open_again() {
        let gate = LaserGate::new();
        let g = gate.close();
        assert!(gate.open(g));
        assert!(gate.passes(true, g));
        assert_eq!(gate.shut(), g, "the generation goes on");
        assert!(!gate.is_open());
        assert!(!gate.passes(true, g), "samples already out are dark");
        assert!(gate.open(g), "the same run lights again");
        assert!(gate.passes(true, g));
        // A close after the shut still ends the run for good.
        gate.shut();
        let g2 = gate.close();
        assert!(!gate.open(g));
        assert!(gate.open(g2));
    }

    #[test]
    fn a_forbidden_gate_refuses_every_open_until_permitted() {
        let gate = LaserGate::new();
        assert!(gate.is_permitted(), "a board without controls");
        let g = gate.close();
        assert!(gate.open(g));
        let g2 = gate.forbid();
        assert_ne!(g, g2, "forbidding ends the run's generation");
        assert!(!gate.is_open() && !gate.passes(true, g));
        assert!(!gate.open(g2), "not even the current generation opens");
        assert!(!gate.open(g));
        gate.permit();
        assert!(!gate.open(g), "the run that was lit stays dark");
        assert!(gate.open(g2), "a new run lights");
    }

    #[test]
    fn generations_wrap_without_touching_the_open_bit() {
        let gate = LaserGate::new();
        gate.state.store(
            GateState {
                generation: u32::MAX >> 1,
                open: true,
            }
            .pack(),
            Ordering::Relaxed,
        );
        assert_eq!(gate.close(), 0);
        assert!(!gate.is_open());
    }
}
