//! The simulated board's status LEDs, stop button and watchdog: the parts
//! behind `laser-app`'s indicator, stop-button and watchdog task bodies
//! (the same bodies the target runs). They record what they did in a
//! [`PanelRecord`]; none of them changes a run's results (the watchdog
//! model reports when the target's would have reset, and the run goes on).

use std::cell::RefCell;
use std::rc::Rc;

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use laser_app::app::{Indicators, Leds, StopButton, WATCHDOG_TIMEOUT_US, Watchdog};

use crate::clock::now_us;
use crate::executor::simulator_work;

/// What the watchdog did.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct WatchdogRecord {
    /// When the firmware started it, µs.
    pub started_at_us: Option<u64>,
    /// Feeds.
    pub feeds: u64,
    /// The last feed (or the start), µs.
    pub last_kick_us: Option<u64>,
    /// When the target's watchdog would have reset the MCU: each gap
    /// between feeds longer than the timeout, at its end, µs.
    pub resets_at_us: Vec<u64>,
}

impl WatchdogRecord {
    /// Records a starvation if more than the timeout passed since the last
    /// kick by `t_us`.
    fn check(&mut self, t_us: u64) {
        if let Some(last) = self.last_kick_us {
            let deadline = last + u64::from(WATCHDOG_TIMEOUT_US);
            if t_us > deadline && self.resets_at_us.last() != Some(&deadline) {
                self.resets_at_us.push(deadline);
            }
        }
    }

    /// The record as of `end_us` (the run's end): a starvation still going
    /// on then counts too.
    pub fn at_end(&self, end_us: u64) -> Self {
        let mut record = self.clone();
        record.check(end_us);
        record
    }
}

/// What the LEDs, the stop button and the watchdog did during a run.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PanelRecord {
    /// What the LEDs showed from when on (µs): one entry per change.
    pub leds: Vec<(u64, Leds)>,
    /// When the stop button was pressed, µs.
    pub button_presses: Vec<u64>,
    /// The watchdog.
    pub watchdog: WatchdogRecord,
}

/// Shared record of one run's panel.
pub type SharedPanel = Rc<RefCell<PanelRecord>>;

/// The LEDs: every change recorded with its time.
pub struct SimLeds(pub SharedPanel);

impl Indicators for SimLeds {
    fn show(&mut self, leds: Leds) {
        simulator_work(|| {
            let mut panel = self.0.borrow_mut();
            if panel.leds.last().map(|(_, shown)| *shown) != Some(leds) {
                panel.leds.push((now_us(), leds));
            }
        });
    }
}

/// The stop button's contacts: a script's `@button` presses them.
#[derive(Default)]
pub struct ButtonContacts(Signal<CriticalSectionRawMutex, ()>);

impl ButtonContacts {
    /// Presses the button once.
    pub fn press(&self) {
        self.0.signal(());
    }
}

/// The stop button: clean contacts, so every press is one press (no
/// debouncing, unlike the target's mechanical switch).
pub struct SimStopButton {
    /// What the script presses.
    pub contacts: Rc<ButtonContacts>,
    /// Where presses are recorded.
    pub panel: SharedPanel,
}

impl StopButton for SimStopButton {
    async fn pressed(&mut self) {
        self.contacts.0.wait().await;
        simulator_work(|| self.panel.borrow_mut().button_presses.push(now_us()));
    }
}

/// The watchdog: records its start and feeds and when the target's would
/// have reset (it never resets the simulation).
pub struct SimWatchdog(pub SharedPanel);

impl SimWatchdog {
    fn kick(&mut self, feed: bool) {
        simulator_work(|| {
            let t_us = now_us();
            let dog = &mut self.0.borrow_mut().watchdog;
            if feed {
                dog.check(t_us);
                dog.feeds += 1;
            } else {
                dog.started_at_us = Some(t_us);
            }
            dog.last_kick_us = Some(t_us);
        });
    }
}

impl Watchdog for SimWatchdog {
    fn start(&mut self) {
        self.kick(false);
    }

    fn feed(&mut self) {
        self.kick(true);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gap_longer_than_the_timeout_is_a_reset_once() {
        let timeout = u64::from(WATCHDOG_TIMEOUT_US);
        let mut dog = WatchdogRecord {
            last_kick_us: Some(1_000),
            ..WatchdogRecord::default()
        };
        dog.check(1_000 + timeout);
        assert!(
            dog.resets_at_us.is_empty(),
            "exactly the timeout is in time"
        );
        dog.check(1_001 + timeout);
        dog.check(9 * timeout);
        assert_eq!(dog.resets_at_us, [1_000 + timeout]);
        assert_eq!(dog.at_end(10 * timeout).resets_at_us.len(), 1);
        dog.last_kick_us = Some(2 * timeout);
        assert_eq!(
            dog.at_end(4 * timeout).resets_at_us,
            [1_000 + timeout, 3 * timeout]
        );
    }
}
