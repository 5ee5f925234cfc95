//! What the simulated DAC output: every sample with its time, as runs of
//! identical samples, and every half buffer.

use laser_app::galvo::DacSample;
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

    pub(super) fn push_half(
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
