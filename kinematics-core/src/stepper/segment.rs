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
    /// respects its nominal rate and acceleration.
    pub fn of(block: &PlannedBlock) -> Self {
        let a = block.accel_steps_per_s2;
        let (v0, v1) = (block.entry_rate_steps_per_s, block.exit_rate_steps_per_s);
        let d = f64::from(block.event_count);
        let meet = libm::sqrt(a * d + 0.5 * (v0 * v0 + v1 * v1));
        let peak = meet.min(block.nominal_rate_steps_per_s).max(v0).max(v1);
        let d_acc = ((peak * peak - v0 * v0) / (2.0 * a)).clamp(0.0, d);
        let d_dec = ((peak * peak - v1 * v1) / (2.0 * a)).clamp(0.0, d - d_acc);
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

    /// Peak (cruise) rate, steps/s.
    pub fn peak_rate_steps_per_s(&self) -> f64 {
        self.peak
    }

    /// Profile rate at `s` events from the block start, steps/s.
    pub fn rate_at(&self, s: f64) -> f64 {
        if s < self.d_acc {
            reachable_f(self.entry, self.accel, s)
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
        let t_acc = (self.peak - self.entry) / a;
        if s <= self.d_acc {
            return (reachable_f(self.entry, a, s) - self.entry) / a;
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

/// Fixed-capacity ring of prepared segments (prep pushes, the step
/// generator pops).
#[derive(Debug, Clone)]
pub struct SegmentQueue<const N: usize> {
    items: [Segment; N],
    head: usize,
    len: usize,
}

impl<const N: usize> Default for SegmentQueue<N> {
    fn default() -> Self {
        Self {
            items: [Segment::default(); N],
            head: 0,
            len: 0,
        }
    }
}

impl<const N: usize> SegmentQueue<N> {
    /// Number of prepared segments.
    pub fn len(&self) -> usize {
        self.len
    }
    /// Whether no segment is prepared.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Whether no further segment fits.
    pub fn is_full(&self) -> bool {
        self.len == N
    }
    /// Appends a segment; gives it back when full.
    pub fn push(&mut self, seg: Segment) -> Result<(), Segment> {
        if self.len == N {
            return Err(seg);
        }
        let Some(slot) = self.items.get_mut((self.head + self.len) % N) else {
            return Err(seg);
        };
        *slot = seg;
        self.len += 1;
        Ok(())
    }
    /// Takes the oldest segment.
    pub fn pop(&mut self) -> Option<Segment> {
        if self.len == 0 {
            return None;
        }
        let seg = *self.items.get(self.head)?;
        // Wrap by compare, not `%`: this runs in the step interrupt.
        self.head += 1;
        if self.head == N {
            self.head = 0;
        }
        self.len -= 1;
        Some(seg)
    }
}

/// The prep stage: pulls blocks from the planner and cuts them into
/// segments of about `segment_s` seconds.
#[derive(Debug, Clone)]
pub struct SegmentPrep {
    timer_hz: f64,
    segment_s: f64,
    current: Option<(StepBlock, Profile)>,
    /// Events of the current block already cut.
    done: u32,
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
            done: 0,
        })
    }

    /// Whether a block is being cut.
    pub fn is_busy(&self) -> bool {
        self.current.is_some()
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
            if queue.push(seg).is_ok() {
                added += 1;
            }
        }
        added
    }

    /// Cuts the next segment, taking a new block from `planner` when the
    /// current one is finished.
    pub fn next_segment<const P: usize>(&mut self, planner: &mut Planner<P>) -> Option<Segment> {
        let starts_block = self.current.is_none();
        if starts_block {
            let b = planner.pop()?;
            let block = StepBlock {
                steps: [b.steps[0].unsigned_abs(), b.steps[1].unsigned_abs()],
                negative: [b.steps[0] < 0, b.steps[1] < 0],
                event_count: b.event_count,
            };
            self.current = Some((block, Profile::of(&b)));
            self.done = 0;
        }
        let (block, profile) = self.current?;
        let remaining = block.event_count - self.done;
        let s0 = f64::from(self.done);
        let want = libm::floor(profile.rate_at(s0) * self.segment_s);
        // Saturating float→int conversion; at least one event.
        let events = (want as u32).clamp(1, remaining);
        let dt = profile.time_at(s0 + f64::from(events)) - profile.time_at(s0);
        let ticks = libm::ceil(dt * self.timer_hz / f64::from(events));
        let period_ticks = (ticks as u32).max(1);
        self.done += events;
        if self.done >= block.event_count {
            self.current = None;
        }
        Some(Segment {
            block,
            starts_block,
            events,
            period_ticks,
        })
    }
}
