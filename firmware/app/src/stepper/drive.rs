//! [`StepperDrive`], what a board's stepper outputs and step timer do.

use super::config::DriverSignals;

/// The board's stepper outputs and step timer.
#[allow(async_fn_in_trait)]
pub trait StepperDrive {
    /// Energises (`true`) or releases the drivers (the board applies the
    /// configured ENABLE polarity).
    fn set_enabled(&mut self, enabled: bool);
    /// The pulse timing and ENABLE polarity from now on (at rest: the
    /// place for any arithmetic the step path would otherwise do).
    fn set_signals(&mut self, signals: DriverSignals);
    /// One step event: DIR to `negative` (high = negative) on both axes,
    /// then — the DIR setup time later when a DIR pin changed — a STEP
    /// pulse of the configured width on each axis in `step`. May return
    /// before the pulse ends (the STM32 board times it with a one-pulse
    /// timer, [`OnePulseTiming`](super::OnePulseTiming)); a pulse still running from the event
    /// before ends before DIR changes.
    fn step(&mut self, step: [bool; 2], negative: [bool; 2]);
    /// Waits until `ticks` step-timer ticks after the previous event (the
    /// schedule does not drift with the time the step took).
    async fn wait_ticks(&mut self, ticks: u32);
    /// The next event is scheduled from now (after the timer was idle).
    fn restart(&mut self);
    /// Whether each axis's limit switch is pressed, `[pan, tilt]` (read
    /// before every step event; inputs without a switch read released).
    fn limits(&mut self) -> [bool; 2];
}
