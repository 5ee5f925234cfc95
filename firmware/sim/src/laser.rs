//! The simulated laser output: the master
//! [`LaserGate`](laser_app::laser_gate::LaserGate) with every change
//! recorded with its time, and the gimbal's laser pin ANDed with it.
//!
//! The gate's hook is a plain `fn`, so the per-simulation state it writes
//! to lives in a thread-local (each simulation runs on one thread, with
//! its own virtual clock).

use std::cell::RefCell;
use std::rc::Rc;

use laser_app::laser_gate::{GateState, LaserGate};
use laser_app::sequencer::LaserSwitch;

use crate::dac::DacRecording;
use crate::recorder::{Recording, SpotSample};

/// Where the gimbal spot is at a time (µs), board cm.
pub type SpotAt = Box<dyn Fn(u64) -> Option<(f64, f64)>>;

struct GimbalLaser {
    recording: Rc<RefCell<Recording>>,
    spot_at: SpotAt,
    /// What the sequencer asked of the pin.
    pin: bool,
    /// What was last recorded (pin AND gate).
    lit: bool,
}

#[derive(Default)]
struct Output {
    dac: Option<Rc<RefCell<DacRecording>>>,
    gate_open: bool,
    gimbal: Option<GimbalLaser>,
}

thread_local! {
    static OUTPUT: RefCell<Output> = RefCell::new(Output::default());
}

/// A new gate (closed, generation 0) whose changes are recorded, with
/// their times, in `dac`'s gate timeline (and switch the gimbal laser of
/// [`GatedLaserPin`]). One per simulation; it replaces this thread's
/// previous one.
pub fn recorded_gate(dac: &Rc<RefCell<DacRecording>>) -> &'static LaserGate {
    OUTPUT.with(|o| {
        *o.borrow_mut() = Output {
            dac: Some(dac.clone()),
            gate_open: false,
            gimbal: None,
        }
    });
    Box::leak(Box::new(LaserGate::with_hook(gate_changed)))
}

fn now_ns() -> u64 {
    crate::clock::now_us() * 1000
}

fn gate_changed(state: GateState) {
    OUTPUT.with(|o| {
        let mut o = o.borrow_mut();
        if let Some(dac) = &o.dac {
            dac.borrow_mut().gate.push((now_ns(), state));
        }
        o.gate_open = state.open;
        o.update_gimbal();
    });
}

impl Output {
    /// Records the gimbal laser when pin AND gate changed: a laser event
    /// and a spot sample (so a trace has a row at every change).
    fn update_gimbal(&mut self) {
        let open = self.gate_open;
        let Some(g) = self.gimbal.as_mut() else {
            return;
        };
        let lit = g.pin && open;
        if lit == g.lit {
            return;
        }
        g.lit = lit;
        let t_us = crate::clock::now_us();
        let mut rec = g.recording.borrow_mut();
        if rec.laser_events.last().is_some_and(|(t, _)| *t == t_us) {
            // Switched back within the same microsecond: no light, no
            // event (a new run closing and reopening the gate).
            rec.laser_events.pop();
            if rec.spot.last().is_some_and(|s| s.t_us == t_us) {
                rec.spot.pop();
            }
            if rec.laser_events.last().is_some_and(|e| e.1) == lit {
                return;
            }
        }
        let spot = (g.spot_at)(t_us);
        rec.laser_events.push((t_us, lit));
        if let Some((x_cm, y_cm)) = spot {
            rec.spot.push(SpotSample {
                t_us,
                x_cm,
                y_cm,
                laser: lit,
            });
        }
    }
}

/// The gimbal's laser pin: records the effective laser (what the
/// sequencer asks AND the gate of [`recorded_gate`]) in `recording`'s
/// laser events, with a spot sample at every change.
pub struct GatedLaserPin(());

impl GatedLaserPin {
    /// The pin for this thread's simulation (call after
    /// [`recorded_gate`]); `spot_at` says where the gimbal spot is.
    pub fn new(recording: Rc<RefCell<Recording>>, spot_at: SpotAt) -> Self {
        OUTPUT.with(|o| {
            o.borrow_mut().gimbal = Some(GimbalLaser {
                recording,
                spot_at,
                pin: false,
                lit: false,
            })
        });
        Self(())
    }
}

impl LaserSwitch for GatedLaserPin {
    fn set(&mut self, on: bool) {
        OUTPUT.with(|o| {
            let mut o = o.borrow_mut();
            if let Some(g) = o.gimbal.as_mut() {
                g.pin = on;
            }
            o.update_gimbal();
        });
    }
}

/// Whether the gimbal laser is lit now (pin AND gate).
pub fn gimbal_lit() -> bool {
    OUTPUT.with(|o| o.borrow().gimbal.as_ref().is_some_and(|g| g.lit))
}
