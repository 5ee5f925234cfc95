//! The simulated galvo DAC: a double buffer read out at the sample rate
//! in virtual time, with the same refill deadlines as the target's
//! timer-triggered DMA, so a loop that is too slow underruns here too.
//!
//! The DAC outputs half after half without gaps. A half's physical buffer
//! is free once the DAC has moved on to the half before it, and must be
//! written before the DAC reaches it. The loop's compute time is modelled
//! by charging `compute_ns_per_sample` per written sample before the
//! deadline check. A late write makes the DAC replay the stale content of
//! each half it reaches, exactly as circular DMA does. Every output sample
//! is recorded with its time.

use std::cell::RefCell;
use std::rc::Rc;

use embassy_time::{Instant, Timer};
use laser_app::galvo::{DacSample, DacStream, Underrun};

/// Every sample the DAC output, in order, with its output time, stored
/// as runs of identical samples (a DAC holding still for minutes costs one
/// entry, not millions).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DacRecording {
    runs: Vec<SampleRun>,
    len: usize,
    /// `(first sample index, halves)` of each underrun: where stale
    /// samples were replayed.
    pub underruns: Vec<(usize, u32)>,
    /// When the loop learned of each underrun (its `write_half` returned
    /// the error), ns.
    pub underrun_detected_ns: Vec<u64>,
    /// Every half buffer output, in order.
    pub halves: Vec<HalfRecord>,
}

/// One half buffer as the DAC output it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HalfRecord {
    /// Index of its first sample in the recording.
    pub first_sample: usize,
    /// When its first sample was output, ns.
    pub start_ns: u64,
    /// When the loop computed the content output (it calls `write_half`
    /// right after filling the half; for a stale replay: the earlier
    /// content the buffer still held), ns.
    pub computed_ns: u64,
    /// Replayed stale content (the loop was late).
    pub stale: bool,
}

/// `count` equal samples from `start_ns`, one per `period_ns`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct SampleRun {
    start_ns: u64,
    period_ns: u64,
    count: u64,
    sample: DacSample,
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

    /// Every sample with its output time (ns), in order.
    pub fn iter(&self) -> impl Iterator<Item = (u64, DacSample)> + '_ {
        self.runs
            .iter()
            .flat_map(|r| (0..r.count).map(move |i| (r.start_ns + i * r.period_ns, r.sample)))
    }

    /// Runs of equal samples: `(start ns, period ns, count, sample)`.
    pub fn runs(&self) -> impl Iterator<Item = (u64, u64, u64, DacSample)> + '_ {
        self.runs
            .iter()
            .map(|r| (r.start_ns, r.period_ns, r.count, r.sample))
    }

    /// `k,t_s,dac_x,dac_y,laser` for every sample (`--dac` file).
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
        computed_ns: u64,
        stale: bool,
    ) {
        self.halves.push(HalfRecord {
            first_sample: self.len,
            start_ns,
            computed_ns,
            stale,
        });
        for (i, &sample) in half.iter().enumerate() {
            let t_ns = start_ns + i as u64 * period_ns;
            self.len += 1;
            if let Some(last) = self.runs.last_mut()
                && last.sample == sample
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
            });
        }
    }
}

/// The simulated DAC (implements [`DacStream`]).
pub struct SimDac {
    half_len: usize,
    /// Period for halves written from now on, ns.
    period_ns: u64,
    /// When the DAC starts the half to be written next (its deadline), ns.
    next_start_ns: u64,
    /// When the DAC started the half before it (the buffer is free from
    /// then), ns.
    free_from_ns: u64,
    /// Index of the next half (selects the physical buffer).
    next_half: u64,
    /// Content, period (ns) and compute time (ns) of the two physical halves.
    buffers: [(Vec<DacSample>, u64, u64); 2],
    compute_ns_per_sample: u64,
    recording: Rc<RefCell<DacRecording>>,
}

impl SimDac {
    /// A DAC with `half_len`-sample halves at `period_ns` per sample,
    /// starting one half period from now (time to fill the first half),
    /// charging `compute_ns_per_sample` of loop time per written sample.
    pub fn new(
        half_len: usize,
        period_ns: u64,
        compute_ns_per_sample: u64,
        recording: Rc<RefCell<DacRecording>>,
    ) -> Self {
        let half_len = half_len.max(1);
        let period_ns = period_ns.max(1);
        let now_ns = Instant::now().as_micros() * 1000;
        Self {
            half_len,
            period_ns,
            next_start_ns: now_ns + half_len as u64 * period_ns,
            free_from_ns: now_ns,
            next_half: 0,
            buffers: [
                (vec![DacSample::default(); half_len], period_ns, now_ns),
                (vec![DacSample::default(); half_len], period_ns, now_ns),
            ],
            compute_ns_per_sample,
            recording,
        }
    }

    fn physical(h: u64) -> usize {
        (h % 2) as usize
    }

    /// The DAC moves on past the half at `next_start_ns` with the content
    /// its buffer holds.
    fn advance(&mut self, written: Option<(&[DacSample], u64)>) {
        // The DAC and its recording: not firmware work.
        crate::executor::simulator_work(|| self.advance_now(written));
    }

    fn advance_now(&mut self, written: Option<(&[DacSample], u64)>) {
        let slot = Self::physical(self.next_half);
        if let Some((samples, computed_ns)) = written {
            let buffer = &mut self.buffers[slot];
            buffer.0.clear();
            buffer.0.extend(samples.iter().copied().take(self.half_len));
            let last = samples.last().copied().unwrap_or_default();
            buffer.0.resize(self.half_len, last);
            buffer.1 = self.period_ns;
            buffer.2 = computed_ns;
        }
        let (content, period_ns, computed_ns) = &self.buffers[slot];
        self.recording.borrow_mut().push_half(
            self.next_start_ns,
            *period_ns,
            content,
            *computed_ns,
            written.is_none(),
        );
        self.free_from_ns = self.next_start_ns;
        self.next_start_ns += self.half_len as u64 * period_ns;
        self.next_half += 1;
    }
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

    async fn write_half(&mut self, samples: &[DacSample]) -> Result<(), Underrun> {
        let computed_ns = Instant::now().as_micros() * 1000;
        let compute_ns = self.compute_ns_per_sample * samples.len() as u64;
        Timer::after_micros(compute_ns.div_ceil(1000)).await;
        let now_ns = Instant::now().as_micros() * 1000;
        let mut halves = 0;
        while now_ns > self.next_start_ns {
            // The DAC reached this half before it was written: stale replay.
            if halves == 0 {
                let at = self.recording.borrow().len();
                self.recording.borrow_mut().underruns.push((at, 0));
            }
            self.advance(None);
            halves += 1;
        }
        if halves > 0 {
            if let Some(last) = self.recording.borrow_mut().underruns.last_mut() {
                last.1 = halves;
            }
        } else if now_ns < self.free_from_ns {
            Timer::at(Instant::from_micros(self.free_from_ns.div_ceil(1000))).await;
        }
        self.advance(Some((samples, computed_ns)));
        if halves > 0 {
            let detected_ns = Instant::now().as_micros() * 1000;
            self.recording
                .borrow_mut()
                .underrun_detected_ns
                .push(detected_ns);
            Err(Underrun { halves })
        } else {
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::executor;
    use crate::safety::galvo_stretches;

    fn lit(x_code: u16) -> DacSample {
        DacSample {
            x_code,
            y_code: 0,
            laser: true,
        }
    }

    #[test]
    fn each_half_records_when_it_was_computed_and_late_halves_replay_stale() {
        let recording = Rc::new(RefCell::new(DacRecording::default()));
        let dac_recording = recording.clone();
        executor::run(
            false,
            1_000_000,
            move |spawner| {
                executor::spawn(&spawner, async move {
                    // 4 samples of 10 µs per half: each half lasts 40 µs.
                    let mut dac = SimDac::new(4, 10_000, 0, dac_recording);
                    for code in [1, 2] {
                        let _ = dac.write_half(&[lit(code); 4]).await;
                    }
                    // The second write waited for its buffer until 40 µs;
                    // the third comes at 140 µs, after its half began at
                    // 120 µs: the DAC replays what that buffer holds.
                    Timer::after_micros(100).await;
                    let late = dac.write_half(&[lit(3); 4]).await;
                    assert!(late.is_err());
                });
            },
            || false,
        );
        let rec = recording.borrow();
        let halves: Vec<(u64, u64, bool)> = rec
            .halves
            .iter()
            .map(|h| (h.start_ns, h.computed_ns, h.stale))
            .collect();
        // Halves 0 and 1 from 40 and 80 µs (both computed at 0), half 2
        // replays half 0's content (computed at 0) from 120 µs, then the
        // late half (computed at 140 µs) from 160 µs.
        assert_eq!(
            halves,
            [
                (40_000, 0, false),
                (80_000, 0, false),
                (120_000, 0, true),
                (160_000, 140_000, false),
            ]
        );
        assert_eq!(rec.underrun_detected_ns, [140_000]);
        let stretches = galvo_stretches(&rec);
        let codes: Vec<(u64, u16, u64)> = stretches
            .iter()
            .map(|s| (s.start_ns, s.x_code, s.count))
            .collect();
        assert_eq!(
            codes,
            [
                (40_000, 1, 4),
                (80_000, 2, 4),
                (120_000, 1, 4),
                (160_000, 3, 4)
            ]
        );
        assert_eq!(stretches[3].computed_ns, 140_000);
    }
}
