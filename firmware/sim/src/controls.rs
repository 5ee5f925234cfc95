//! The simulated board's laser controls: the remote interlock and key
//! switch (set by a script's `@interlock open|closed` and `@key off|on`)
//! and the emission indicator, behind `laser-app`'s laser-controls task.
//! Every change is recorded with its time ([`ControlsRecord`]) for the
//! safety checker.
//!
//! The wiring starts as on a bench with the jumpers fitted: the interlock
//! closed and the key on. The firmware still starts latched (no emission
//! until `arm`).

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use laser_app::app::LaserControls;
use laser_app::laser_controls::ControlInputs;

use crate::clock::now_us;
use crate::executor::simulator_work;

/// What the controls did: each input's and the indicator's level from
/// when on (µs), one entry per change, the first at 0.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ControlsRecord {
    /// The interlock loop closed.
    pub interlock_closed: Vec<(u64, bool)>,
    /// The key switch on.
    pub key_on: Vec<(u64, bool)>,
    /// The emission indicator on.
    pub indicator: Vec<(u64, bool)>,
}

/// The level of `changes` (as recorded in a [`ControlsRecord`]) at `t_us`.
pub fn level_at(changes: &[(u64, bool)], t_us: u64) -> bool {
    changes
        .iter()
        .take_while(|(t, _)| *t <= t_us)
        .last()
        .is_some_and(|(_, on)| *on)
}

/// The wiring the script changes: the two inputs' levels and an edge
/// signal for the firmware.
pub struct ControlWiring {
    interlock_closed: Cell<bool>,
    key_on: Cell<bool>,
    edge: Signal<CriticalSectionRawMutex, ()>,
    record: Rc<RefCell<ControlsRecord>>,
}

impl ControlWiring {
    /// Bench wiring (interlock jumper fitted, key on), recorded from 0.
    pub fn bench() -> Self {
        Self {
            interlock_closed: Cell::new(true),
            key_on: Cell::new(true),
            edge: Signal::new(),
            record: Rc::new(RefCell::new(ControlsRecord {
                interlock_closed: vec![(0, true)],
                key_on: vec![(0, true)],
                indicator: vec![(0, false)],
            })),
        }
    }

    /// Opens (`false`) or closes the interlock loop now.
    pub fn set_interlock(&self, closed: bool) {
        self.interlock_closed.set(closed);
        self.record
            .borrow_mut()
            .interlock_closed
            .push((now_us(), closed));
        self.edge.signal(());
    }

    /// Turns the key switch off (`false`) or on now.
    pub fn set_key(&self, on: bool) {
        self.key_on.set(on);
        self.record.borrow_mut().key_on.push((now_us(), on));
        self.edge.signal(());
    }

    /// What happened so far.
    pub fn record(&self) -> ControlsRecord {
        self.record.borrow().clone()
    }
}

/// The board part: reads the wiring, drives the recorded indicator.
pub struct SimLaserControls(pub Rc<ControlWiring>);

impl LaserControls for SimLaserControls {
    fn read(&mut self) -> ControlInputs {
        ControlInputs {
            interlock_closed: self.0.interlock_closed.get(),
            key_on: self.0.key_on.get(),
        }
    }

    async fn changed(&mut self) {
        self.0.edge.wait().await;
    }

    fn set_indicator(&mut self, on: bool) {
        simulator_work(|| {
            let mut record = self.0.record.borrow_mut();
            if record.indicator.last().map(|(_, shown)| *shown) != Some(on) {
                record.indicator.push((now_us(), on));
            }
        });
    }
}
