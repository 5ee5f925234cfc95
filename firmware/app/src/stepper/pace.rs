//! The step timer's schedule: each event a number of ticks after the one
//! before it, on embassy-time deadlines, so the time a step takes never
//! makes the schedule drift. Boards whose step timer is embassy-time hold
//! one and answer [`super::StepperDrive::wait_ticks`] and
//! [`super::StepperDrive::restart`] with it.

use embassy_time::{Duration, Instant, Timer};

/// Deadline of the next step event.
#[derive(Debug, Clone, Copy)]
pub struct StepPace {
    next: Instant,
}

impl StepPace {
    /// A schedule that starts at the next [`StepPace::restart`].
    pub const fn new() -> Self {
        Self { next: Instant::MIN }
    }

    /// Waits until `ticks` embassy-time ticks after the previous event's
    /// deadline.
    pub async fn wait_ticks(&mut self, ticks: u32) {
        self.next += Duration::from_ticks(u64::from(ticks));
        Timer::at(self.next).await;
    }

    /// The next event is scheduled from now (after the timer was idle).
    pub fn restart(&mut self) {
        self.next = Instant::now();
    }
}

impl Default for StepPace {
    fn default() -> Self {
        Self::new()
    }
}
