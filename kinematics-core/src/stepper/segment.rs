//! Segment prep: cuts the planned trapezoid (or triangle) profile of the
//! block being executed into short constant-rate segments, ahead of the
//! step generator. Each segment is a whole number of step events and one
//! timer period per event; the period is rounded up, so a segment's rate
//! never exceeds the profile's mean rate over that stretch.
//!
//! Runs in a low-priority task with `f64`; the step generator only reads
//! the prepared integers.

use super::motion::{MAX_TIMER_HZ, MotionError};
use super::planner::{PlannedBlock, Planner};
use crate::numeric::clamp;

/// What the step generator needs of a block: step counts and directions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StepBlock {
    /// Steps per axis, `[pan, tilt]` (unsigned).
    pub steps: [u32; 2],
    /// Whether each axis moves in the negative direction (DIR level).
    pub negative: [bool; 2],
    /// Step events of the block (the larger of `steps`, ≥ 1).
    pub event_count: u32,
}

/// A constant-rate stretch of a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Segment {
    /// The block this segment belongs to.
    pub block: StepBlock,
    /// Whether this is the block's first segment (resets Bresenham).
    pub starts_block: bool,
    /// Step events in this segment (≥ 1).
    pub events: u32,
    /// Timer ticks between events (≥ 1).
    pub period_ticks: u32,
    /// The segment's rate over its block's cruise rate, ‰ (0..=1000; M4
    /// laser power follows it).
    pub speed_permille: u16,
}

/// A trapezoid velocity profile over `d` step events, rates in steps/s,
/// acceleration in steps/s².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    d: f64,
    entry: f64,
    peak: f64,
    exit: f64,
    accel: f64,
    /// Events spent accelerating and decelerating.
    d_acc: f64,
    d_dec: f64,
}

impl Profile {
    /// The fastest profile of `block` from its entry to its exit rate that
    /// respects its nominal rate and acceleration; an entry above the
    /// nominal rate (a feed override lowered it) decelerates to it first.
    pub fn of(block: &PlannedBlock) -> Self {
        let a = block.accel_steps_per_s2;
        let (v0, v1) = (block.entry_rate_steps_per_s, block.exit_rate_steps_per_s);
        let d = f64::from(block.event_count);
        let meet = libm::sqrt(a * d + 0.5 * (v0 * v0 + v1 * v1));
        let peak = if meet >= v0 {
            meet.min(block.nominal_rate_steps_per_s).max(v1)
        } else {
            v0
        };
        // `numeric::clamp`, not `f64::clamp`: its panic path formats floats
        // (10 KB of flash on the target).
        let d_acc = clamp(libm::fabs(peak * peak - v0 * v0) / (2.0 * a), 0.0, d);
        let d_dec = clamp((peak * peak - v1 * v1) / (2.0 * a), 0.0, d - d_acc);
        Self {
            d,
            entry: v0,
            peak,
            exit: v1,
            accel: a,
            d_acc,
            d_dec,
        }
    }

    /// Rate `s` events into the first phase (towards the peak), steps/s.
    fn first_phase_rate(&self, s: f64) -> f64 {
        if self.peak >= self.entry {
            reachable_f(self.entry, self.accel, s)
        } else {
            libm::sqrt((self.entry * self.entry - 2.0 * self.accel * s).max(0.0))
        }
    }

    /// Peak (cruise) rate, steps/s.
    pub fn peak_rate_steps_per_s(&self) -> f64 {
        self.peak
    }

    /// Profile rate at `s` events from the block start, steps/s.
    pub fn rate_at(&self, s: f64) -> f64 {
        if s < self.d_acc {
            self.first_phase_rate(s)
        } else if s <= self.d - self.d_dec {
            self.peak
        } else {
            // Measured back from the block end, v² = v₁² + 2·a·(d − s):
            // no cancellation of peak² against 2·a·d_dec, which near the
            // end (rate → exit) cost up to 1e-4 steps/s, 1e-9 s per event.
            reachable_f(self.exit, self.accel, (self.d - s).max(0.0)).min(self.peak)
        }
    }

    /// Time from the block start to `s` events, s.
    pub fn time_at(&self, s: f64) -> f64 {
        let a = self.accel;
        let t_acc = libm::fabs(self.peak - self.entry) / a;
        if s <= self.d_acc {
            return libm::fabs(self.first_phase_rate(s) - self.entry) / a;
        }
        let cruise_end = self.d - self.d_dec;
        if s <= cruise_end {
            return t_acc + (s - self.d_acc) / self.peak;
        }
        t_acc + (cruise_end - self.d_acc) / self.peak + (self.peak - self.rate_at(s)) / a
    }
}

fn reachable_f(rate: f64, accel: f64, events: f64) -> f64 {
    libm::sqrt(rate * rate + 2.0 * accel * events)
}

/// Blocks a hold can take back: the generator's and one per prepared
/// segment (the step queue's 8).
const TAKE_BACK: usize = 9;

mod feed;
mod take_back;

/// Fixed-capacity ring of prepared segments (prep pushes at the back,
/// the step generator pops at the front; the ring wraps by compare, no
/// division, in the step interrupt).
pub type SegmentQueue<const N: usize> = crate::ring::Ring<Segment, N>;

impl Segment {
    /// No steps (the step generator's state before its first segment).
    pub const EMPTY: Self = Self {
        block: StepBlock {
            steps: [0; 2],
            negative: [false; 2],
            event_count: 0,
        },
        starts_block: false,
        events: 0,
        period_ticks: 0,
        speed_permille: 0,
    };
}

/// The block being cut and where the cutting is.
#[derive(Debug, Clone, Copy)]
struct Cutting {
    block: StepBlock,
    /// Profile of events `start..end` of the block.
    profile: Profile,
    accel: f64,
    start: u32,
    /// Events of the block already cut.
    done: u32,
    /// Events of the block to cut (fewer than the block's on a hold).
    end: u32,
    /// Whether the next segment is the block's first.
    fresh: bool,
    /// The block's feed before the override, steps/s (0: fixed rate).
    feed_rate: f64,
    /// The block's cruise rate (feed override applied), steps/s (0: a
    /// hold's taken-back stretch).
    nominal: f64,
}

impl Cutting {
    /// Rate where the cutting is, steps/s.
    fn rate_now(&self) -> f64 {
        self.profile.rate_at(f64::from(self.done - self.start))
    }

    /// Replaces the rest of the profile by a deceleration at the limit
    /// from `rate` (steps/s). Returns the exit rate: 0 when it stops
    /// within the block (the cutting then ends where it stops).
    fn decelerate_from(&mut self, rate: f64) -> f64 {
        let left = self.block.event_count - self.done;
        let a = self.accel;
        let stop_events = libm::ceil(rate * rate / (2.0 * a));
        let (events, exit) = if stop_events <= f64::from(left) {
            // In range (≤ left): the cast is exact.
            (stop_events as u32, 0.0)
        } else {
            let exit = libm::sqrt((rate * rate - 2.0 * a * f64::from(left)).max(0.0));
            (left, exit)
        };
        self.profile = Profile::of(&PlannedBlock {
            event_count: events,
            nominal_rate_steps_per_s: rate,
            accel_steps_per_s2: a,
            entry_rate_steps_per_s: rate,
            exit_rate_steps_per_s: exit,
            ..PlannedBlock::default()
        });
        self.start = self.done;
        self.end = self.done + events;
        exit
    }
}

/// The prep stage: pulls blocks from the planner and cuts them into
/// segments of about `segment_s` seconds.
#[derive(Debug, Clone)]
pub struct SegmentPrep {
    timer_hz: f64,
    segment_s: f64,
    current: Option<Cutting>,
    /// On a hold: the rate the next block starts at, steps/s.
    hold_rate: Option<f64>,
    /// On a hold: the rest of the blocks taken back from the step queue
    /// (a segment per block: its events left), cut before the planner's.
    taken_back: SegmentQueue<TAKE_BACK>,
    /// Acceleration of the last block taken from the planner, steps/s².
    accel: f64,
}

impl SegmentPrep {
    /// A prep stage for a step timer of `timer_hz` Hz (1..=
    /// [`MAX_TIMER_HZ`]) cutting segments of about `segment_s` seconds
    /// (0.1 ms..=100 ms; grbl uses a few ms).
    ///
    /// Errors: [`MotionError::InvalidTiming`].
    pub fn new(timer_hz: u32, segment_s: f64) -> Result<Self, MotionError> {
        if timer_hz == 0 || timer_hz > MAX_TIMER_HZ || !(1.0e-4..=0.1).contains(&segment_s) {
            return Err(MotionError::InvalidTiming);
        }
        Ok(Self {
            timer_hz: f64::from(timer_hz),
            segment_s,
            current: None,
            hold_rate: None,
            taken_back: SegmentQueue::new(),
            accel: 0.0,
        })
    }

    /// Whether a block is being cut.
    pub fn is_busy(&self) -> bool {
        self.current.is_some() || !self.taken_back.is_empty()
    }

    /// Whether a hold is decelerating (until it has cut its last segment).
    pub fn is_holding(&self) -> bool {
        self.hold_rate.is_some()
    }

    /// A feed hold (grbl's): from where the cutting is, the rest is cut
    /// as a deceleration at each block's acceleration limit along the
    /// queued path, to rest; the blocks after the stop are dropped from
    /// `planner`. The segments already prepared run as they are (the
    /// deceleration follows them). Nothing to do at rest.
    pub fn hold<const P: usize>(&mut self, planner: &mut Planner<P>) {
        let rate = match self.current.as_mut() {
            Some(c) => {
                let now = c.rate_now();
                c.decelerate_from(now)
            }
            // The prepared segments end at the next block's entry rate.
            None => planner.block(0).map_or(0.0, |b| b.entry_rate_steps_per_s),
        };
        if rate > 0.0 {
            self.hold_rate = Some(rate);
        } else {
            self.stop_holding(planner);
        }
    }

    fn stop_holding<const P: usize>(&mut self, planner: &mut Planner<P>) {
        planner.clear();
        self.hold_rate = None;
        self.taken_back.clear();
    }

    /// Forgets the block being cut and any hold (after the step generator
    /// was halted: nothing prepared will run).
    pub fn reset(&mut self) {
        self.current = None;
        self.hold_rate = None;
        self.taken_back.clear();
    }

    /// Prepares segments into `queue` until it is full or the planner has
    /// no more blocks. Returns the number of segments added.
    pub fn fill<const P: usize, const Q: usize>(
        &mut self,
        planner: &mut Planner<P>,
        queue: &mut SegmentQueue<Q>,
    ) -> usize {
        let mut added = 0;
        while !queue.is_full() {
            let Some(seg) = self.next_segment(planner) else {
                break;
            };
            // Not full (checked above): the push succeeds.
            if queue.push_back(seg).is_ok() {
                added += 1;
            }
        }
        added
    }

    /// Takes the next block from `planner` (decelerating on a hold).
    fn start_block<const P: usize>(&mut self, planner: &mut Planner<P>) -> Option<Cutting> {
        if let Some(cutting) = self.resume_taken_back() {
            return Some(cutting);
        }
        let b = planner.pop()?;
        self.accel = b.accel_steps_per_s2;
        let mut cutting = Cutting {
            block: StepBlock {
                steps: [b.steps[0].unsigned_abs(), b.steps[1].unsigned_abs()],
                negative: [b.steps[0] < 0, b.steps[1] < 0],
                event_count: b.event_count,
            },
            profile: Profile::of(&b),
            accel: b.accel_steps_per_s2,
            start: 0,
            done: 0,
            end: b.event_count,
            fresh: true,
            feed_rate: b.feed_rate_steps_per_s,
            nominal: b.nominal_rate_steps_per_s,
        };
        if let Some(rate) = self.hold_rate {
            let exit = cutting.decelerate_from(rate);
            self.hold_rate = Some(exit);
        }
        Some(cutting)
    }

    /// Cuts the next segment, taking a new block from `planner` when the
    /// current one is finished.
    pub fn next_segment<const P: usize>(&mut self, planner: &mut Planner<P>) -> Option<Segment> {
        if self.current.is_none() {
            self.current = self.start_block(planner);
            if self.current.is_none() {
                // Nothing left: a hold ends here too.
                self.hold_rate = None;
                return None;
            }
        }
        let mut c = self.current?;
        if c.done >= c.end {
            // A hold that stopped right here.
            self.current = None;
            self.stop_holding(planner);
            return None;
        }
        let s0 = f64::from(c.done - c.start);
        let want = libm::floor(c.profile.rate_at(s0) * self.segment_s);
        // Saturating float→int conversion; at least one event.
        let events = (want as u32).max(1).min(c.end - c.done);
        let dt = c.profile.time_at(s0 + f64::from(events)) - c.profile.time_at(s0);
        let ticks = libm::ceil(dt * self.timer_hz / f64::from(events)).max(1.0);
        let speed = if c.nominal > 0.0 {
            clamp(self.timer_hz / ticks / c.nominal, 0.0, 1.0)
        } else {
            0.0
        };
        let segment = Segment {
            block: c.block,
            starts_block: c.fresh,
            events,
            period_ticks: ticks as u32,
            // In 0..=1000: the cast is exact.
            speed_permille: libm::round(speed * 1000.0) as u16,
        };
        c.done += events;
        c.fresh = false;
        self.current = (c.done < c.end).then_some(c);
        if c.done >= c.end && self.hold_rate == Some(0.0) {
            self.stop_holding(planner);
        }
        Some(segment)
    }
}
