//! Homing (`home`, `$H` on the stepper): for each axis with a switch, in
//! the order pan, tilt — seek towards the switch at the seek speed until
//! it closes (at most the soft-limit span plus two pull-offs), back off
//! the pull-off distance, approach again at the latch speed until it
//! closes, take that step as the switch's joint angle (the zero), pull
//! off (a switch not found: the axis goes back to where its seek
//! began, so the position stays known). The step timer halts the steps
//! before the first step event that finds the switch closed, so the
//! latch point is the first microstep inside the switch.

use embassy_futures::select::{Either3, select, select3};
use embassy_time::Timer;

use super::config::StepperConfig;
use super::link::{
    HomingFailure, LimitMode, StepperEvent, StepperLink, StepperRefusal, StepperRequest,
};
use super::task::{REFILL_PERIOD, Running};
use crate::log;

/// How a homing move ended.
enum Jogged {
    /// The seek found its switch.
    Hit,
    /// It ran its length.
    Done,
}

impl Running {
    /// Homes the axes with switches; the position afterwards is the
    /// pull-off point of the last axis, in steps of the homed zero.
    pub(super) async fn home(&mut self, link: &StepperLink) -> Result<[i32; 2], HomingFailure> {
        let config = *self.motion.config();
        if config.homing.dir == [0; 2] {
            return Err(HomingFailure::NoSwitches);
        }
        // A stop before it decelerates to rest first.
        while !(link.is_idle() && self.motion.is_planned_out()) {
            self.refill(link);
            let _ = select(link.drained.wait(), Timer::after(REFILL_PERIOD)).await;
        }
        let _ = link.take_halt();
        self.stopping = false;
        self.deferred = None;
        let start = link.position_steps();
        self.motion.rest_at(start);
        let mut result = self.home_axes(&config, link).await;
        if let Err(HomingFailure::NotFound(axis)) = result {
            result = self.back_to(link, usize::from(axis), start, &config).await;
        }
        link.set_limit_mode(LimitMode::Guard);
        self.motion.rest_at(link.position_steps());
        result.map(|()| link.position_steps())
    }

    async fn home_axes(
        &mut self,
        config: &StepperConfig,
        link: &StepperLink,
    ) -> Result<(), HomingFailure> {
        let h = config.homing;
        for (axis, dir) in h.dir.into_iter().enumerate() {
            if dir == 0 {
                continue;
            }
            let steps = |deg: f64| {
                config
                    .axis(axis)
                    .angle_to_steps(f64::from(dir) * deg)
                    .map_err(|_| HomingFailure::BadConfig)
            };
            let travel = steps(config.max_deg[axis] - config.min_deg[axis] + 2.0 * h.pulloff_deg)?;
            let pull = steps(h.pulloff_deg)?;
            let seek = LimitMode::Seek(axis as u8);
            let not_found = HomingFailure::NotFound(axis as u8);
            if let Jogged::Done = self.jog(link, axis, travel, h.seek_deg_s, seek).await? {
                return Err(not_found);
            }
            self.jog(link, axis, -pull, h.seek_deg_s, LimitMode::Ignore)
                .await?;
            if link.is_pressed(axis) {
                return Err(HomingFailure::StillPressed(axis as u8));
            }
            if let Jogged::Done = self.jog(link, axis, 2 * pull, h.latch_deg_s, seek).await? {
                return Err(not_found);
            }
            // The latch step is the first inside the switch: the switch
            // closed within the step before it, at half a step back on
            // average (so the zero is within one step, rounding included).
            let inside = f64::from(dir) * config.deg_per_step() / 2.0;
            let at = config
                .axis(axis)
                .angle_to_steps(h.switch_deg[axis] + inside - config.zero_deg[axis])
                .map_err(|_| HomingFailure::BadConfig)?;
            link.set_position(axis, at);
            self.motion.rest_at(link.position_steps());
            self.jog(link, axis, -pull, h.seek_deg_s, LimitMode::Ignore)
                .await?;
            log::info!("stepper: axis {} homed", axis);
        }
        Ok(())
    }

    /// Axis `axis`'s switch was not found: back to its steps at the
    /// start of the cycle (`start`; its seek began there: an axis before
    /// it moves only itself) at the seek speed, so the axes end where the
    /// cycle found them (a failed `$H` repeated does not wind the axis
    /// round). Returns the failure to report.
    async fn back_to(
        &mut self,
        link: &StepperLink,
        axis: usize,
        start: [i32; 2],
        config: &StepperConfig,
    ) -> Result<(), HomingFailure> {
        let back = start[axis & 1].wrapping_sub(link.position_steps()[axis & 1]);
        if back != 0 {
            let speed = config.homing.seek_deg_s;
            self.jog(link, axis, back, speed, LimitMode::Ignore).await?;
        }
        Err(HomingFailure::NotFound(axis as u8))
    }

    /// Moves axis `axis` by `steps` at `speed_deg_s` with the limit check
    /// `mode`, until it ends or (seeking) its switch closes.
    async fn jog(
        &mut self,
        link: &StepperLink,
        axis: usize,
        steps: i32,
        speed_deg_s: f64,
        mode: LimitMode,
    ) -> Result<Jogged, HomingFailure> {
        link.set_limit_mode(mode);
        let mut delta = [0; 2];
        delta[axis & 1] = steps;
        self.motion
            .jog(delta, speed_deg_s)
            .map_err(|_| HomingFailure::BadConfig)?;
        loop {
            if link.take_halt() {
                self.motion.rest_at(link.position_steps());
                return match link.take_seek_hit() {
                    true => Ok(Jogged::Hit),
                    false => Err(HomingFailure::Interrupted),
                };
            }
            self.refill(link);
            if link.is_idle() && self.motion.is_planned_out() {
                return Ok(Jogged::Done);
            }
            let woke = select3(
                link.drained.wait(),
                Timer::after(REFILL_PERIOD),
                link.requests.receive(),
            );
            match woke.await {
                Either3::Third(StepperRequest::MoveTo { seq, .. }) => {
                    let why = StepperRefusal::Busy;
                    link.events.send(StepperEvent::Refused { seq, why }).await;
                }
                // A feed hold while homing stops it, as a stop does.
                Either3::Third(
                    StepperRequest::Stop
                    | StepperRequest::Halt
                    | StepperRequest::Home
                    | StepperRequest::Hold,
                ) => link.halt(),
                Either3::Third(
                    StepperRequest::Resume
                    | StepperRequest::FeedOverride { .. }
                    | StepperRequest::Junction { .. },
                )
                | Either3::First(())
                | Either3::Second(()) => {}
            }
        }
    }
}
