//! The simulated laser output: the master
//! [`LaserGate`] with every change
//! recorded with its time, and the gimbal's laser pin ANDed with it.
//!
//! The gate's hook is a plain `fn`, so the per-simulation state it writes
//! to lives in a thread-local (each simulation runs on one thread, with
//! its own virtual clock).

use std::cell::RefCell;
use std::rc::Rc;

use laser_app::laser_gate::{GateState, LaserGate};
use laser_app::sequencer::{LaserPower, LaserSwitch};

use crate::dac::DacRecording;
use crate::recorder::{Recording, SpotSample};

/// Where the gimbal spot is at a time (µs), board cm.
pub type SpotAt = Box<dyn Fn(u64) -> Option<(f64, f64)>>;

struct GimbalLaser {
    recording: Rc<RefCell<Recording>>,
    spot_at: SpotAt,
    /// What the sequencer asked of the output.
    pin: LaserPower,
    /// What was last recorded (the output's level, dark while the gate is
    /// closed).
    power: LaserPower,
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
    /// Records the gimbal laser when its effective level (pin, dark
    /// while the gate is closed) changed: a power change, a laser event
    /// when it switched on or off, and a spot sample (so a trace has a row
    /// at every change).
    fn update_gimbal(&mut self) {
        let open = self.gate_open;
        let Some(g) = self.gimbal.as_mut() else {
            return;
        };
        let power = if open { g.pin } else { LaserPower::OFF };
        if power == g.power {
            return;
        }
        let was_lit = g.power.is_on();
        g.power = power;
        let t_us = crate::clock::now_us();
        let mut rec = g.recording.borrow_mut();
        record_power(&mut rec.laser_power, t_us, power.per_mille());
        let lit = power.is_on();
        if rec.spot.last().is_some_and(|s| s.t_us == t_us) {
            // One row per microsecond: the last level of it.
            rec.spot.pop();
        }
        if lit != was_lit {
            if rec.laser_events.last().is_some_and(|(t, _)| *t == t_us) {
                // Switched back within the same microsecond: no light, no
                // event (a new run closing and reopening the gate).
                rec.laser_events.pop();
                if rec.laser_events.last().is_some_and(|e| e.1) == lit {
                    return;
                }
            }
            rec.laser_events.push((t_us, lit));
        }
        let spot = (g.spot_at)(t_us);
        if let Some((x_cm, y_cm)) = spot {
            rec.spot.push(SpotSample {
                t_us,
                x_cm,
                y_cm,
                laser: lit,
                power: power.per_mille(),
            });
        }
    }
}

/// Appends a level change at `t_us` to `changes`, keeping one per
/// microsecond (the last) and none that changes nothing.
fn record_power(changes: &mut Vec<(u64, u16)>, t_us: u64, per_mille: u16) {
    if changes.last().is_some_and(|(t, _)| *t == t_us) {
        changes.pop();
    }
    if changes.last().map_or(0, |(_, p)| *p) != per_mille {
        changes.push((t_us, per_mille));
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
                pin: LaserPower::OFF,
                power: LaserPower::OFF,
            })
        });
        Self(())
    }
}

impl LaserSwitch for GatedLaserPin {
    fn set(&mut self, power: LaserPower) {
        OUTPUT.with(|o| {
            let mut o = o.borrow_mut();
            if let Some(g) = o.gimbal.as_mut() {
                g.pin = power;
            }
            o.update_gimbal();
        });
    }
}

/// Whether the gimbal laser is lit now (pin AND gate).
pub fn gimbal_lit() -> bool {
    OUTPUT.with(|o| o.borrow().gimbal.as_ref().is_some_and(|g| g.power.is_on()))
}
