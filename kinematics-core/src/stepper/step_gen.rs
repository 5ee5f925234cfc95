//! The step generator: executes prepared segments, one step event per
//! timer interrupt, with multi-axis Bresenham. Integer adds and compares
//! only — no float, no division, no planning — so it can run in the step
//! timer's interrupt.

use super::segment::{Segment, SegmentQueue, StepBlock};

/// What one timer interrupt does on the pins.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepTick {
    /// Whether each axis gets a STEP pulse now, `[pan, tilt]`.
    pub step: [bool; 2],
    /// DIR level of each axis (true = negative); set before the pulse.
    pub negative: [bool; 2],
    /// Timer ticks until the next interrupt.
    pub period_ticks: u32,
}

/// Bresenham state over the current block plus the current segment.
#[derive(Debug, Clone)]
pub struct StepGenerator {
    block: StepBlock,
    counter: [u32; 2],
    segment: Option<Segment>,
    /// Events left in the current segment.
    left: u32,
    /// Position in microsteps since creation, `[pan, tilt]`.
    position: [i32; 2],
    /// Timer period of the segment being (or last) executed, ticks.
    period_ticks: u32,
    /// [`Segment::speed_permille`] of the segment being (or last)
    /// executed; 0 at rest.
    speed_permille: u16,
}

impl Default for StepGenerator {
    fn default() -> Self {
        Self::new()
    }
}

impl StepGenerator {
    /// A generator at rest at position 0 (usable in a `static`).
    pub const fn new() -> Self {
        Self {
            block: Segment::EMPTY.block,
            counter: [0; 2],
            segment: None,
            left: 0,
            position: [0; 2],
            period_ticks: 0,
            speed_permille: 0,
        }
    }

    /// Position counted from the emitted steps, microsteps `[pan, tilt]`.
    pub fn position_steps(&self) -> [i32; 2] {
        self.position
    }

    /// Redefines the position, microsteps `[pan, tilt]` (homing sets
    /// the zero; at rest).
    pub fn set_position(&mut self, position: [i32; 2]) {
        self.position = position;
    }

    /// Whether a segment is being executed.
    pub fn is_running(&self) -> bool {
        self.segment.is_some()
    }

    /// The block in progress (the last one loaded) and the timer period
    /// of the segment running or last run, ticks (`None` after a halt or
    /// before the first segment).
    pub fn executing(&self) -> (StepBlock, Option<u32>) {
        (
            self.block,
            (self.period_ticks > 0).then_some(self.period_ticks),
        )
    }

    /// The running segment's rate over its block's cruise rate, ‰
    /// (0..=1000; 0 at rest or after a halt).
    pub fn speed_permille(&self) -> u16 {
        self.speed_permille
    }

    /// Drops the current segment (a hard stop: steps halt at once).
    pub fn halt(&mut self) {
        self.segment = None;
        self.left = 0;
        self.period_ticks = 0;
        self.speed_permille = 0;
    }

    /// One timer interrupt: the next step event of the current segment,
    /// loading the next prepared segment when needed. `None` when nothing
    /// is prepared (the timer should stop).
    pub fn tick<const Q: usize>(&mut self, queue: &mut SegmentQueue<Q>) -> Option<StepTick> {
        if self.left == 0 {
            let Some(seg) = queue.pop_front() else {
                self.speed_permille = 0;
                return None;
            };
            self.load(seg);
        }
        let seg = self.segment?;
        let mut step = [false; 2];
        let block = self.block;
        let axes = step
            .iter_mut()
            .zip(self.counter.iter_mut())
            .zip(self.position.iter_mut());
        let plan = block.steps.iter().zip(block.negative.iter());
        for (((fired, counter), position), (&steps, &negative)) in axes.zip(plan) {
            // counter ≤ event_count ≤ 2^30 and steps ≤ 2^30: no overflow.
            *counter += steps;
            if *counter > block.event_count {
                *counter -= block.event_count;
                *fired = true;
                *position = if negative {
                    position.wrapping_sub(1)
                } else {
                    position.wrapping_add(1)
                };
            }
        }
        self.left -= 1;
        if self.left == 0 {
            self.segment = None;
        }
        Some(StepTick {
            step,
            negative: self.block.negative,
            period_ticks: seg.period_ticks,
        })
    }

    fn load(&mut self, seg: Segment) {
        if seg.starts_block {
            self.block = seg.block;
            // Start at ⌈n/2⌉ (grbl's signed −⌊n/2⌋ offset by n): with the
            // strict `> n` test the counter then ends every block at
            // ⌈n/2⌉ ∈ [1, n], so each axis emits exactly its steps (a
            // ⌊n/2⌋ start loses the only step of a one-event block) and
            // stays within half a step of the line.
            let n = seg.block.event_count;
            self.counter = [n - (n >> 1); 2];
        }
        self.left = seg.events;
        self.period_ticks = seg.period_ticks;
        self.speed_permille = seg.speed_permille;
        self.segment = (seg.events > 0).then_some(seg);
    }
}
