//! The sequencer's side of the laser controls: `arm`, the controls'
//! line in `status` and grbl's `Door` state in `?`. The controls
//! themselves (debounce, latch, indicator delay) run in their own task
//! and forbid the master gate directly (`crate::laser_controls`).

use super::machine::{Action, ActionSink, Core};
use crate::laser_controls::{ControlsState, ControlsView, LatchCause};

/// The reply to `arm` on a board without the controls.
const NO_CONTROLS: &str = "this board has no laser controls (no interlock, key or indicator)";

impl Core {
    /// The controls' state as the shell read it from their link, before
    /// each event (`None`: the board has none).
    pub(super) fn note_laser_controls(&mut self, view: Option<ControlsView>) {
        self.controls = view;
    }

    /// `arm`: asks the controls task to arm with the saved indicator
    /// delay; refused while the interlock reads open or the key off.
    pub(super) fn arm(&mut self, out: &mut dyn ActionSink) {
        let Some(view) = self.controls else {
            return self.error(out, NO_CONTROLS);
        };
        if let Some(refusal) = view.arm_refusal() {
            return self.error(out, refusal.describe());
        }
        // 1–60 s (the parameter's range): fits in u32 ms.
        let delay_ms = (self.settings.emission_delay_s * 1000.0) as u32;
        out.act(Action::ArmLaser { delay_ms });
        self.ok(out);
    }

    /// `status`: the controls' line.
    pub(super) fn status_controls_line(&self, out: &mut dyn ActionSink) {
        let Some(view) = self.controls else {
            return self.data(out, format_args!("laser controls: none on this board"));
        };
        let state = match view.state {
            ControlsState::Latched(cause) => cause.describe(),
            ControlsState::Arming => "arming (indicator on, laser after the delay)",
            ControlsState::Armed => "armed (indicator on)",
        };
        self.data(
            out,
            format_args!(
                "laser controls: interlock {}, key {}, {}",
                if view.inputs.interlock_closed {
                    "closed"
                } else {
                    "open"
                },
                if view.inputs.key_on { "on" } else { "off" },
                state
            ),
        );
    }

    /// Who asked for a stop request: the stop button, or the laser
    /// controls when they latched emission off.
    pub(super) fn stop_request_cause(&self) -> &'static str {
        match self.controls.map(|view| view.state) {
            Some(ControlsState::Latched(LatchCause::InterlockOpened)) => "interlock opened",
            Some(ControlsState::Latched(LatchCause::KeyOff)) => "key switch off",
            _ => "stop button",
        }
    }

    /// grbl's `Door:n` for `?` while the controls keep the laser off.
    pub(super) fn door_substate(&self) -> Option<u8> {
        self.controls.and_then(|view| view.door_substate())
    }
}

#[cfg(test)]
mod tests;
