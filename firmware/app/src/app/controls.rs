//! The laser-controls task: reads the interlock and key switch, runs
//! [`ControlsLogic`], forbids or permits the master laser gate, drives the
//! emission indicator and publishes the state for `status` and `?`.

use embassy_futures::select::{Either3, select3};
use embassy_time::{Duration, Instant, Timer};

use super::board::LaserControls;
use crate::command::CommandLink;
use crate::laser_controls::{ControlsLink, ControlsLogic, ControlsState, ControlsView};
use crate::laser_gate::LaserGate;
use crate::log;
use crate::outbound::LineKind;

/// The controls task reads the inputs at least this often, besides every
/// edge the board reports.
pub const CONTROLS_POLL: Duration = Duration::from_millis(5);

/// The laser controls: interlock, key switch, emission indicator, `arm`.
pub struct LaserControlsTask<C> {
    pub(super) controls: C,
    pub(super) link: &'static ControlsLink,
    pub(super) gate: &'static LaserGate,
    pub(super) command: &'static CommandLink,
}

impl<C: LaserControls> LaserControlsTask<C> {
    /// Runs the controls from power-up (latched: no emission until armed).
    pub async fn run(mut self) -> ! {
        let mut logic = ControlsLogic::new();
        let mut shown = None;
        let mut arm_request = None;
        loop {
            let now_us = Instant::now().as_micros();
            logic.sample(now_us, self.controls.read());
            if let Some(delay_ms) = arm_request.take()
                && let Err(refused) = logic.arm(now_us, u64::from(delay_ms) * 1000)
            {
                log::warning!("laser controls: arm refused ({})", refused.describe());
            }
            let view = ControlsView::of(&logic);
            self.apply(&logic, view, shown);
            shown = Some(view);
            let poll = Instant::from_micros(now_us) + CONTROLS_POLL;
            let wake = logic
                .next_deadline_us()
                .map_or(poll, |at| poll.min(Instant::from_micros(at)));
            if let Either3::Second(delay_ms) = select3(
                self.controls.changed(),
                self.link.arm.wait(),
                Timer::at(wake),
            )
            .await
            {
                arm_request = Some(delay_ms);
            }
        }
    }

    /// Puts `view` into effect: the gate first (dark at once), then the
    /// indicator, the published state and a notice for each change; a
    /// latch after arming also stops the run (a stop request).
    fn apply(&mut self, logic: &ControlsLogic, view: ControlsView, shown: Option<ControlsView>) {
        let permitted = logic.emission_permitted();
        if permitted != self.gate.is_permitted() {
            if permitted {
                self.gate.permit();
            } else {
                self.gate.forbid();
            }
        }
        self.controls.set_indicator(logic.indicator_on());
        self.link.publish(view);
        if shown.map(|s| s.state) == Some(view.state) {
            return;
        }
        let text = match view.state {
            ControlsState::Latched(cause) => cause.describe(),
            ControlsState::Arming => "armed: emission indicator on, laser enabled after the delay",
            ControlsState::Armed => "laser enabled",
        };
        log::info!("laser controls: {}", text);
        let was_arming = shown.is_some_and(|s| !matches!(s.state, ControlsState::Latched(_)));
        if was_arming && matches!(view.state, ControlsState::Latched(_)) {
            // The run that may have been lit stops (as the stop button):
            // the gate is dark already, its drawing is cut short.
            self.command.stop_request.signal(());
        }
        if shown.is_some() {
            let _ = self
                .command
                .outbound
                .push_fmt(LineKind::Notice, format_args!("MSG:laser controls: {text}"));
        }
    }
}

impl LaserControlsTask<super::board::NoLaserControls> {
    /// A board without the controls never gets this task: its spawner's
    /// `laser_controls` hook is this.
    pub fn unreachable(self) -> ! {
        match self.controls {}
    }
}
