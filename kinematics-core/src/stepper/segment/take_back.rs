//! A feed hold that brakes at once (grbl re-plans its segment prep for
//! the hold): the segments prepared but not yet executed are taken back
//! from the step queue, and the deceleration is cut from the end of the
//! segment the step generator is executing, along the same blocks.

use super::super::planner::Planner;
use super::{Cutting, Profile, Segment, SegmentPrep, SegmentQueue, StepBlock, TAKE_BACK};

/// Adds `events` of `block` to the runs taken back: a new run when the
/// block starts there (`starts`) or nothing is taken back yet, else onto
/// the newest run.
fn add_run(back: &mut SegmentQueue<TAKE_BACK>, block: StepBlock, events: u32, starts: bool) {
    if !starts && let Some(last) = back.back_mut() {
        last.events += events;
        return;
    }
    // One run per prepared segment at most, plus the generator's: fits.
    let _ = back.push_back(Segment {
        block,
        starts_block: starts,
        events,
        period_ticks: 0,
        speed_permille: 0,
    });
}

impl SegmentPrep {
    /// A feed hold from where the step generator is: `executing` is its
    /// block in progress and the period of the segment it runs or last
    /// ran (`None`: none since a halt); `queue` is the step queue, whose prepared
    /// segments are taken back (call under the step timer's lock). The
    /// deceleration at the limit starts where the running segment ends,
    /// from its rate, along the rest of its block and the blocks after it.
    /// With nothing running nor prepared, as [`Self::hold`].
    pub fn hold_now<const P: usize, const Q: usize>(
        &mut self,
        planner: &mut Planner<P>,
        executing: (StepBlock, Option<u32>),
        queue: &mut SegmentQueue<Q>,
    ) {
        let (block, period) = executing;
        let Some(period) = period.or_else(|| queue.front().map(|s| s.period_ticks)) else {
            return self.hold(planner);
        };
        let mut back = SegmentQueue::new();
        add_run(&mut back, block, 0, false);
        let mut left = 0;
        while let Some(seg) = queue.pop_front() {
            add_run(&mut back, seg.block, seg.events, seg.starts_block);
            left += u64::from(seg.events);
        }
        if let Some(c) = self.current.take() {
            add_run(&mut back, c.block, c.end - c.done, c.fresh);
            left += u64::from(c.end - c.done);
        }
        for b in (0..planner.len()).filter_map(|i| planner.block(i)) {
            left += u64::from(b.event_count);
        }
        self.taken_back = back;
        // From the running segment's rate, but no faster than the path
        // left allows to stop on (a plan already braking to its end).
        let fits = libm::sqrt(2.0 * self.accel * left as f64);
        let rate = (self.timer_hz / f64::from(period.max(1))).min(fits);
        if rate > 0.0 {
            self.hold_rate = Some(rate);
        } else {
            self.stop_holding(planner);
        }
    }

    /// The next block taken back by [`Self::hold_now`] that has events
    /// left, decelerating from the hold's rate.
    pub(super) fn resume_taken_back(&mut self) -> Option<Cutting> {
        loop {
            let run = self.taken_back.pop_front()?;
            if run.events == 0 {
                continue;
            }
            let done = run.block.event_count.saturating_sub(run.events);
            let a = self.accel;
            let mut cutting = Cutting {
                block: run.block,
                profile: Profile {
                    d: 0.0,
                    entry: 0.0,
                    peak: 0.0,
                    exit: 0.0,
                    accel: a,
                    d_acc: 0.0,
                    d_dec: 0.0,
                },
                accel: a,
                start: done,
                done,
                end: run.block.event_count,
                fresh: run.starts_block,
                feed_rate: 0.0,
                nominal: 0.0,
            };
            let exit = cutting.decelerate_from(self.hold_rate.unwrap_or(0.0));
            self.hold_rate = Some(exit);
            return Some(cutting);
        }
    }
}
