//! The simulated galvo DAC: a double buffer read out at the sample rate
//! in virtual time, with the same refill deadlines as the target's
//! timer-triggered DMA, so a loop that is too slow underruns here too.
//!
//! Like the target's DMA, the DAC starts once the loop has primed both
//! halves, then outputs half after half without gaps. A half's physical
//! buffer is free once the DAC has moved on to the half before it, and
//! must be written before the DAC reaches it. The loop's compute time is
//! modelled by charging `compute_ns_per_sample` per sample the loop
//! computed, before the deadline check (a hold the loop lets the DAC
//! replay costs nothing). A late write makes the DAC replay the stale
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
use laser_app::galvo::{DacSample, DacStream, Half, Underrun};
use laser_app::laser_gate::GateState;

/// Every sample the DAC output, in order, with its output time, stored
/// as runs of identical samples (a DAC holding still for minutes costs one
/// entry, not millions).
///
/// [`Self::iter`], [`Self::runs`] and [`Self::csv`] give the *effective*
/// laser: a sample's laser bit AND the master gate at its output time
/// (open, at the generation the sample was computed under); replayed
/// stale halves are dark. [`Self::stream_runs`] gives the bits as the
/// loop computed them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DacRecording {
    runs: Vec<SampleRun>,
    len: usize,
    /// `(first sample index, halves)` of each underrun: where stale
    /// samples were replayed.
    pub underruns: Vec<(usize, u32)>,
    /// Every change of the master laser gate: (time ns, new state), in
    /// order. Empty: the gate was never recorded (see
    /// [`crate::laser::recorded_gate`]), and no sample is lit.
    pub gate: Vec<(u64, GateState)>,
    /// When the loop learned of each underrun, ns.
    pub underrun_detected_ns: Vec<u64>,
    /// Every half buffer output, in order.
    pub halves: Vec<HalfRecord>,
}

/// `count` equal samples from `start_ns`, one per `period_ns`, computed
/// under gate generation `generation` (`None`: a stale replay).
#[derive(Debug, Clone, Copy, PartialEq)]
struct SampleRun {
    start_ns: u64,
    period_ns: u64,
    count: u64,
    sample: DacSample,
    generation: Option<u32>,
}

impl DacRecording {
    /// Samples output so far.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether nothing was output.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Every sample with its output time (ns), in order; laser effective.
    pub fn iter(&self) -> impl Iterator<Item = (u64, DacSample)> + '_ {
        self.effective_runs()
            .into_iter()
            .flat_map(|r| (0..r.count).map(move |i| (r.start_ns + i * r.period_ns, r.sample)))
    }

    /// Runs of equal samples: `(start ns, period ns, count, sample)`;
    /// laser effective.
    pub fn runs(&self) -> impl Iterator<Item = (u64, u64, u64, DacSample)> + '_ {
        self.effective_runs()
            .into_iter()
            .map(|r| (r.start_ns, r.period_ns, r.count, r.sample))
    }

    /// Runs as the loop computed them, before the gate:
    /// `(start ns, period ns, count, sample, generation)`; generation
    /// `None` for a stale replay.
    pub fn stream_runs(
        &self,
    ) -> impl Iterator<Item = (u64, u64, u64, DacSample, Option<u32>)> + '_ {
        self.runs
            .iter()
            .map(|r| (r.start_ns, r.period_ns, r.count, r.sample, r.generation))
    }

    /// The gate's state at `t_ns` (closed at generation 0 before its first
    /// recorded change).
    pub fn gate_at(&self, t_ns: u64) -> GateState {
        let i = self.gate.partition_point(|(t, _)| *t <= t_ns);
        match i.checked_sub(1).and_then(|i| self.gate.get(i)) {
            Some((_, state)) => *state,
            None => GateState {
                generation: 0,
                open: false,
            },
        }
    }

    /// The recorded runs with the laser bit ANDed with the gate: lit runs
    /// split where the gate changed.
    fn effective_runs(&self) -> Vec<SampleRun> {
        let mut out: Vec<SampleRun> = Vec::with_capacity(self.runs.len());
        let mut push = |run: SampleRun| {
            if let Some(last) = out.last_mut()
                && last.sample == run.sample
                && last.period_ns == run.period_ns
                && last.start_ns + last.count * last.period_ns == run.start_ns
            {
                last.count += run.count;
            } else {
                out.push(run);
            }
        };
        for run in &self.runs {
            let (Some(generation), true) = (run.generation, run.sample.laser) else {
                push(SampleRun {
                    sample: DacSample {
                        laser: false,
                        ..run.sample
                    },
                    ..*run
                });
                continue;
            };
            let mut k = 0;
            while k < run.count {
                let t_ns = run.start_ns + k * run.period_ns;
                let lit = self.gate_at(t_ns).passes(true, generation);
                // Samples up to the next gate change share its state.
                let next_change = self.gate.partition_point(|(t, _)| *t <= t_ns);
                let until = match self.gate.get(next_change) {
                    Some((t, _)) => (t - run.start_ns).div_ceil(run.period_ns).min(run.count),
                    None => run.count,
                }
                .max(k + 1);
                push(SampleRun {
                    start_ns: t_ns,
                    count: until - k,
                    sample: DacSample {
                        laser: lit,
                        ..run.sample
                    },
                    ..*run
                });
                k = until;
            }
        }
        out
    }

    /// `k,t_s,dac_x,dac_y,laser` for every sample (`--dac` file), laser
    /// effective.
    pub fn csv(&self) -> String {
        let mut out = String::from("k,t_s,dac_x,dac_y,laser\n");
        for (k, (t_ns, s)) in self.iter().enumerate() {
            out.push_str(&format!(
                "{k},{:.6},{},{},{}\n",
                t_ns as f64 * 1e-9,
                s.x_code,
                s.y_code,
                u8::from(s.laser)
            ));
        }
        out
    }

    fn push_half(
        &mut self,
        start_ns: u64,
        period_ns: u64,
        half: &[DacSample],
        generation: Option<u32>,
    ) {
        for (i, &sample) in half.iter().enumerate() {
            let t_ns = start_ns + i as u64 * period_ns;
            self.len += 1;
            if let Some(last) = self.runs.last_mut()
                && last.sample == sample
                && last.generation == generation
                && last.period_ns == period_ns
                && last.start_ns + last.count * period_ns == t_ns
            {
                last.count += 1;
                continue;
            }
            self.runs.push(SampleRun {
                start_ns: t_ns,
                period_ns,
                count: 1,
                sample,
                generation,
            });
        }
    }
}

/// One half buffer as the DAC output it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HalfRecord {
    /// Index of its first sample in the recording.
    pub first_sample: usize,
    /// When its first sample was output, ns.
    pub start_ns: u64,
    /// When the loop computed the content (or chose to repeat a hold), ns.
    pub computed_ns: u64,
    /// Replayed stale content (the loop was late).
    pub stale: bool,
}

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
            recording,
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
        let compute_ns = self.compute_ns_per_sample.get() * computed;
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
mod tests {
    use super::*;
    use crate::executor;
    use laser_app::laser_gate::LaserGate;

    /// 100 samples of 10 µs: 1 ms halves.
    const HALF: usize = 100;
    const PERIOD_NS: u64 = 10_000;

    fn lit(x_code: u16) -> DacSample {
        DacSample {
            x_code,
            y_code: 2048,
            laser: true,
        }
    }

    fn half(samples: &[DacSample], generation: u32) -> Half<'_> {
        Half {
            samples,
            generation,
            computed: samples.len(),
        }
    }

    /// Runs `body` with a DAC (cost `cost_ns` per sample) and a recorded
    /// gate; returns the recording.
    fn with_dac<F>(
        cost_ns: u64,
        body: impl FnOnce(SimDac, &'static LaserGate) -> F + 'static,
    ) -> DacRecording
    where
        F: Future<Output = ()> + 'static,
    {
        let recording = Rc::new(RefCell::new(DacRecording::default()));
        let gate = crate::laser::recorded_gate(&recording);
        let dac = SimDac::new(HALF, PERIOD_NS, cost_ns, recording.clone());
        let done = Rc::new(Cell::new(false));
        let finished = done.clone();
        let end = executor::run(
            false,
            1_000_000,
            move |spawner| {
                executor::spawn(&spawner, async move {
                    body(dac, gate).await;
                    finished.set(true);
                })
            },
            move || done.get(),
        );
        assert_eq!(end, executor::RunEnd::Stopped);
        recording.borrow().clone()
    }

    #[test]
    fn output_starts_once_both_halves_are_primed_and_is_gapless() {
        let rec = with_dac(5_000, |mut dac, gate| async move {
            assert!(gate.open(0));
            let a = [lit(100); HALF];
            let b = [lit(200); HALF];
            // Priming is never late, however slow the loop.
            assert!(dac.write_half(half(&a, 0)).await.is_ok());
            assert!(dac.write_half(half(&b, 0)).await.is_ok());
            for _ in 0..3 {
                assert!(dac.write_half(half(&a, 0)).await.is_ok());
            }
        });
        assert!(rec.underruns.is_empty());
        let samples: Vec<_> = rec.iter().collect();
        assert_eq!(samples.len(), 5 * HALF);
        for w in samples.windows(2) {
            assert_eq!(w[1].0 - w[0].0, PERIOD_NS, "gapless");
        }
        assert!(samples.iter().all(|(_, s)| s.laser));
    }

    #[test]
    fn a_late_half_is_an_underrun_and_its_replay_is_dark() {
        let rec = with_dac(0, |mut dac, gate| async move {
            assert!(gate.open(0));
            let a = [lit(100); HALF];
            let b = [lit(200); HALF];
            dac.write_half(half(&a, 0)).await.unwrap();
            dac.write_half(half(&b, 0)).await.unwrap();
            // Late by two and a half halves.
            Timer::after_micros(3_500).await;
            let late = dac.write_half(half(&a, 0)).await;
            assert_eq!(late, Err(Underrun { halves: 2 }));
        });
        assert_eq!(rec.underruns, vec![(2 * HALF, 2)]);
        let samples: Vec<_> = rec.iter().map(|(_, s)| s).collect();
        assert_eq!(samples.len(), 5 * HALF);
        assert!(samples[..2 * HALF].iter().all(|s| s.laser));
        // The stale replays keep their codes (the mirrors get them) but
        // never the laser.
        assert!(samples[2 * HALF..4 * HALF].iter().all(|s| !s.laser));
        assert_eq!(samples[2 * HALF].x_code, 100);
        assert_eq!(samples[3 * HALF].x_code, 200);
        assert!(samples[4 * HALF..].iter().all(|s| s.laser));
    }

    #[test]
    fn closing_the_gate_darkens_samples_already_handed_over() {
        let rec = with_dac(0, |mut dac, gate| async move {
            assert!(gate.open(0));
            let a = [lit(100); HALF];
            dac.write_half(half(&a, 0)).await.unwrap();
            dac.write_half(half(&a, 0)).await.unwrap();
            // Both halves (2 ms of lit samples) are in the DAC.
            Timer::after_micros(500).await;
            let generation = gate.close();
            // A half computed before the close stays dark even once the
            // gate is open again for a new run; the new run's half shines.
            dac.write_half(half(&a, 0)).await.unwrap();
            assert!(gate.open(generation));
            dac.write_half(half(&[lit(300); HALF], generation))
                .await
                .unwrap();
        });
        let samples: Vec<_> = rec.iter().collect();
        assert_eq!(samples.len(), 4 * HALF);
        for (t_ns, s) in &samples {
            let want = *t_ns < 500_000 || s.x_code == 300;
            assert_eq!(s.laser, want, "at {t_ns} ns");
        }
        // The stream itself was lit: only the gate made it dark.
        assert!(rec.stream_runs().all(|(_, _, _, s, _)| s.laser));
    }

    #[test]
    fn repeating_a_hold_costs_nothing_and_is_never_an_underrun() {
        let hold = DacSample {
            x_code: 2048,
            y_code: 2048,
            laser: false,
        };
        // 1 ms per computed sample: any written half would be late.
        let rec = with_dac(1_000_000, move |mut dac, _| async move {
            let h = [hold; HALF];
            assert!(!dac.holds(hold), "not before it is primed");
            // Both halves of the double buffer.
            for _ in 0..2 {
                dac.write_half(Half {
                    samples: &h,
                    generation: 0,
                    computed: 0,
                })
                .await
                .unwrap();
            }
            assert!(dac.holds(hold));
            assert!(!dac.holds(DacSample { x_code: 0, ..hold }));
            for i in 0..200 {
                dac.repeat_half().await;
                if i % 17 == 0 {
                    // The loop is late now and then: still just a replay.
                    Timer::after_micros(2_700).await;
                }
            }
        });
        assert!(rec.underruns.is_empty());
        let samples: Vec<_> = rec.iter().collect();
        assert!(samples.len() >= 202 * HALF);
        for w in samples.windows(2) {
            assert_eq!(w[1].0 - w[0].0, PERIOD_NS, "gapless");
        }
        assert!(samples.iter().all(|(_, s)| *s == hold));
    }
}
