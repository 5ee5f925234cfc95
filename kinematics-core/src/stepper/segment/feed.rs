//! The feed override on the fly (grbl re-plans on an override change):
//! the queued blocks at a programmed feed get the new cruise rate and the
//! block being cut is re-profiled from where the cutting is, so the
//! change shows within the segments already prepared.

use super::super::motion::MIN_RATE_STEPS_PER_S;
use super::super::planner::{PlannedBlock, Planner};
use super::{Profile, SegmentPrep};
use crate::numeric::clamp;

impl SegmentPrep {
    /// Feed override `scale` (1 = 100 %) from now on: every move at a
    /// programmed feed cruises at its feed × `scale`, within
    /// `max_rate_steps_per_s`; the block being cut changes speed from
    /// where its cutting is, at its acceleration limit, and may end
    /// slower (the planner's next block then starts slower). Nothing
    /// changes during a hold.
    pub fn set_feed_scale<const P: usize>(
        &mut self,
        scale: f64,
        max_rate_steps_per_s: f64,
        planner: &mut Planner<P>,
    ) {
        if !(scale.is_finite() && scale > 0.0) || self.hold_rate.is_some() {
            return;
        }
        let rate_of = |feed: f64| clamp(feed * scale, MIN_RATE_STEPS_PER_S, max_rate_steps_per_s);
        planner.rescale(rate_of);
        let Some(c) = self.current.as_mut().filter(|c| c.feed_rate > 0.0) else {
            return;
        };
        let nominal = rate_of(c.feed_rate);
        let (rate, left) = (c.rate_now(), c.end - c.done);
        // No slower at the end than the new cruise (or what braking from
        // here at the limit allows), no faster than planned.
        let floor = libm::sqrt((rate * rate - 2.0 * c.accel * f64::from(left)).max(0.0));
        let exit = c.profile.exit.min(nominal.max(floor));
        c.profile = Profile::of(&PlannedBlock {
            event_count: left,
            nominal_rate_steps_per_s: nominal,
            accel_steps_per_s2: c.accel,
            entry_rate_steps_per_s: rate,
            exit_rate_steps_per_s: exit,
            ..PlannedBlock::default()
        });
        c.start = c.done;
        c.nominal = nominal;
        planner.limit_head_entry(exit);
    }
}
