//! The simulated galvo DAC: a double buffer read out at the sample rate
//! in virtual time, with the same refill deadlines as the target's
//! timer-triggered DMA, so a loop that is too slow underruns here too.
//!
//! Like the target's DMA, the DAC starts once the loop has primed both
//! halves, then outputs half after half without gaps. A half's physical
//! buffer is free once the DAC has moved on to the half before it, and
//! must be written before the DAC reaches it. The loop's compute time is
//! what the half's work ([`Half::work`]: samples per phase, steps started
//! and prepared) costs on the Cortex-M4F by the cost model fitted to
//! `cargo xtask bench-m4` ([`M4_COST`]), plus `compute_ns_per_sample` per
//! computed sample (0 unless a test slows the loop down), charged before
//! the deadline check (a hold the loop lets the DAC replay costs
//! nothing). A late write makes the DAC replay the stale
//! content of each half it reaches, exactly as circular DMA does, with
//! the laser masked off (the replay is an underrun, and the target's DMA
//! interrupt stops the laser stream).
//!
//! Every output sample is recorded with its time, the gate generation it
//! was computed under, and every change of the master
//! [`LaserGate`](laser_app::laser_gate::LaserGate) with its time: the
//! recording's laser column is the *effective* laser (sample AND gate).

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use embassy_time::{Instant, Timer};
use laser_app::galvo::{DacSample, DacStream, Half, M4_COST, Underrun};

mod recording;

pub use recording::{DacRecording, HalfRecord};

/// A physical half buffer: content, sample period (ns), and the gate
/// generation it was computed under.
#[derive(Debug, Clone)]
struct Buffer {
    samples: Vec<DacSample>,
    period_ns: u64,
    generation: u32,
    /// When the loop computed it, ns.
    computed_ns: u64,
}

/// How the DAC comes to output a half.
enum Output {
    /// The loop wrote it in time (or let it repeat a hold): its content.
    Fresh,
    /// The loop was late: stale content, laser masked off.
    Stale,
}

/// The simulated DAC (implements [`DacStream`]).
pub struct SimDac {
    half_len: usize,
    /// Period for halves written from now on, ns.
    period_ns: u64,
    /// Halves written before the DAC started (it starts after two).
    primed: usize,
    /// When the DAC starts the half to be written next (its deadline), ns.
    next_start_ns: u64,
    /// When the DAC started the half before it (the buffer is free from
    /// then), ns.
    free_from_ns: u64,
    /// Index of the next half (selects the physical buffer).
    next_half: u64,
    /// The two physical halves.
    buffers: [Buffer; 2],
    /// Loop time charged per computed sample, ns (shared: a test can
    /// slow the loop down mid-run).
    compute_ns_per_sample: Rc<Cell<u64>>,
    /// Charge the loop's work at the M4's cost ([`M4_COST`]).
    m4_cost: bool,
    recording: Rc<RefCell<DacRecording>>,
}

impl SimDac {
    /// A DAC with `half_len`-sample halves at `period_ns` per sample,
    /// charging `compute_ns_per_sample` of loop time per computed sample.
    /// It starts output once the loop has written both halves.
    pub fn new(
        half_len: usize,
        period_ns: u64,
        compute_ns_per_sample: u64,
        recording: Rc<RefCell<DacRecording>>,
    ) -> Self {
        let half_len = half_len.max(1);
        let period_ns = period_ns.max(1);
        let buffer = Buffer {
            samples: vec![DacSample::default(); half_len],
            period_ns,
            generation: 0,
            computed_ns: 0,
        };
        Self {
            half_len,
            period_ns,
            primed: 0,
            next_start_ns: 0,
            free_from_ns: 0,
            next_half: 0,
            buffers: [buffer.clone(), buffer],
            compute_ns_per_sample: Rc::new(Cell::new(compute_ns_per_sample)),
            m4_cost: true,
            recording,
        }
    }

    /// The same DAC with the loop's work free (only
    /// `compute_ns_per_sample` charged): to compare what the planners
    /// draw, e.g. `planner seed`, whose M4 cost underruns.
    pub fn without_m4_cost(self) -> Self {
        Self {
            m4_cost: false,
            ..self
        }
    }

    /// The loop time charged per computed sample, ns: set it to slow the
    /// loop down (or speed it up) from now on.
    pub fn compute_cost(&self) -> Rc<Cell<u64>> {
        self.compute_ns_per_sample.clone()
    }

    fn physical(h: u64) -> usize {
        (h % 2) as usize
    }

    fn started(&self) -> bool {
        self.primed >= 2
    }

    fn store(&mut self, slot: usize, half: &Half<'_>, computed_ns: u64) {
        let buffer = &mut self.buffers[slot];
        buffer.samples.clear();
        buffer
            .samples
            .extend(half.samples.iter().copied().take(self.half_len));
        let last = half.samples.last().copied().unwrap_or_default();
        buffer.samples.resize(self.half_len, last);
        buffer.period_ns = self.period_ns;
        buffer.generation = half.generation;
        buffer.computed_ns = computed_ns;
    }

    /// The DAC moves on past the half at `next_start_ns` with the content
    /// its buffer holds.
    fn advance(&mut self, output: Output) {
        // The DAC and its recording: not firmware work.
        crate::executor::simulator_work(|| self.advance_now(output));
    }

    fn advance_now(&mut self, output: Output) {
        let buffer = &self.buffers[Self::physical(self.next_half)];
        let generation = match output {
            Output::Fresh => Some(buffer.generation),
            Output::Stale => None,
        };
        let first_sample = self.recording.borrow().len();
        self.recording.borrow_mut().halves.push(HalfRecord {
            first_sample,
            start_ns: self.next_start_ns,
            computed_ns: buffer.computed_ns,
            stale: generation.is_none(),
        });
        self.recording.borrow_mut().push_half(
            self.next_start_ns,
            buffer.period_ns,
            &buffer.samples,
            generation,
        );
        self.free_from_ns = self.next_start_ns;
        self.next_start_ns += self.half_len as u64 * buffer.period_ns;
        self.next_half += 1;
    }

    /// Skips the halves the DAC has already begun (stale replays);
    /// returns how many.
    fn catch_up(&mut self, now_ns: u64, output: fn() -> Output) -> u32 {
        let mut halves = 0;
        while now_ns > self.next_start_ns {
            self.advance(output());
            halves += 1;
        }
        halves
    }

    async fn wait_until_free(&self) {
        let now_ns = now_ns();
        if now_ns < self.free_from_ns {
            Timer::at(Instant::from_micros(self.free_from_ns.div_ceil(1000))).await;
        }
    }
}

fn now_ns() -> u64 {
    Instant::now().as_micros() * 1000
}

impl DacStream for SimDac {
    /// Allowed for comparison with the time-optimal planner, and charged
    /// its M4 cost ([`M4_COST`]`.bisection_axis`): a seed-planned pattern
    /// underruns here as it would on the M4.
    const F64_PLANNING: bool = true;

    fn half_len(&self) -> usize {
        self.half_len
    }

    fn set_sample_period(&mut self, period_s: f64) {
        if period_s.is_finite() && period_s > 0.0 {
            self.period_ns = (period_s * 1e9).round().max(1.0) as u64;
        }
    }

    fn holds(&self, sample: DacSample) -> bool {
        self.started()
            && self
                .buffers
                .iter()
                .all(|b| b.period_ns == self.period_ns && b.samples.iter().all(|s| *s == sample))
    }

    async fn write_half(&mut self, half: Half<'_>) -> Result<(), Underrun> {
        // The loop computed the half just before handing it over.
        let computed_ns = now_ns();
        let computed = half.computed.min(half.samples.len()) as u64;
        // What the loop did, at the Cortex-M4F's cost (bench-m4's figures),
        // plus any extra per-sample cost a test sets.
        let m4_ns = if self.m4_cost {
            M4_COST.ns(&half.work)
        } else {
            0
        };
        let compute_ns = m4_ns + self.compute_ns_per_sample.get() * computed;
        Timer::after_micros(compute_ns.div_ceil(1000)).await;
        if !self.started() {
            // Priming: the DAC starts once both halves are written.
            self.store(self.primed, &half, computed_ns);
            self.primed += 1;
            if self.started() {
                self.next_start_ns = now_ns();
                self.advance(Output::Fresh);
                self.advance(Output::Fresh);
            }
            return Ok(());
        }
        let at = self.recording.borrow().len();
        let halves = self.catch_up(now_ns(), || Output::Stale);
        if halves > 0 {
            // The DAC reached these halves before they were written.
            self.recording.borrow_mut().underruns.push((at, halves));
            self.recording
                .borrow_mut()
                .underrun_detected_ns
                .push(now_ns());
        } else {
            self.wait_until_free().await;
        }
        self.store(Self::physical(self.next_half), &half, computed_ns);
        self.advance(Output::Fresh);
        if halves > 0 {
            Err(Underrun { halves })
        } else {
            Ok(())
        }
    }

    async fn repeat_half(&mut self) {
        if !self.started() {
            return;
        }
        // Both halves hold the same hold: a replay, however late, is
        // what the loop wants output.
        if self.catch_up(now_ns(), || Output::Fresh) == 0 {
            self.wait_until_free().await;
        }
        // The loop chose now to output its hold again.
        let slot = Self::physical(self.next_half);
        self.buffers[slot].computed_ns = now_ns();
        self.advance(Output::Fresh);
    }
}

#[cfg(test)]
mod tests;
