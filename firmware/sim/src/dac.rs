//! The simulated galvo DAC: a double buffer read out at the sample rate
//! in virtual time, with the same refill deadlines as the target's
//! timer-triggered DMA, so a loop that is too slow underruns here too.
//!
//! Half `h` is output during `[start + h·H, start + (h+1)·H)` (`H` = half
//! length × sample period). Its physical buffer is free once the DAC has
//! moved on to half `h − 1`, and must be written before half `h` starts.
//! The loop's compute time is modelled by charging
//! `compute_ns_per_sample` per written sample before the deadline check.
//! A late write makes the DAC replay the stale content of each half it
//! reaches, exactly as circular DMA does, and every output sample is
//! recorded.

use std::cell::RefCell;
use std::rc::Rc;

use embassy_time::{Instant, Timer};
use laser_app::galvo::{DacSample, DacStream, Underrun};

/// Every sample the DAC output, in order: sample `k` was output at
/// `start_us + k · period_us`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DacRecording {
    /// Time of sample 0, µs.
    pub start_us: u64,
    /// Sample period, µs.
    pub period_us: u64,
    /// The output samples.
    pub samples: Vec<DacSample>,
    /// `(first sample index, halves)` of each underrun: where stale
    /// samples were replayed.
    pub underruns: Vec<(usize, u32)>,
}

impl DacRecording {
    /// `k,t_s,dac_x,dac_y,laser` for every sample (`--dac` file).
    pub fn csv(&self) -> String {
        let mut out = String::from("k,t_s,dac_x,dac_y,laser\n");
        for (k, s) in self.samples.iter().enumerate() {
            let t_us = self.start_us + k as u64 * self.period_us;
            out.push_str(&format!(
                "{k},{:.6},{},{},{}\n",
                t_us as f64 * 1e-6,
                s.x_code,
                s.y_code,
                u8::from(s.laser)
            ));
        }
        out
    }
}

/// The simulated DAC (implements [`DacStream`]).
pub struct SimDac {
    half_len: usize,
    period_us: u64,
    start_us: u64,
    /// Index of the next half to write.
    next_half: u64,
    /// Content of the two physical halves.
    buffers: [Vec<DacSample>; 2],
    compute_ns_per_sample: u64,
    recording: Rc<RefCell<DacRecording>>,
}

impl SimDac {
    /// A DAC with `half_len`-sample halves at `period_us` per sample,
    /// starting one half period from now (time to fill the first half),
    /// charging `compute_ns_per_sample` of loop time per sample.
    pub fn new(
        half_len: usize,
        period_us: u64,
        compute_ns_per_sample: u64,
        recording: Rc<RefCell<DacRecording>>,
    ) -> Self {
        let half_len = half_len.max(1);
        let period_us = period_us.max(1);
        let start_us = Instant::now().as_micros() + half_len as u64 * period_us;
        {
            let mut rec = recording.borrow_mut();
            rec.start_us = start_us;
            rec.period_us = period_us;
        }
        Self {
            half_len,
            period_us,
            start_us,
            next_half: 0,
            buffers: [
                vec![DacSample::default(); half_len],
                vec![DacSample::default(); half_len],
            ],
            compute_ns_per_sample,
            recording,
        }
    }

    fn half_us(&self) -> u64 {
        self.half_len as u64 * self.period_us
    }

    /// Start of half `h`'s output, µs.
    fn half_start_us(&self, h: u64) -> u64 {
        self.start_us + h * self.half_us()
    }

    fn physical(h: u64) -> usize {
        (h % 2) as usize
    }
}

impl DacStream for SimDac {
    fn half_len(&self) -> usize {
        self.half_len
    }

    async fn write_half(&mut self, samples: &[DacSample]) -> Result<(), Underrun> {
        let compute_us = (self.compute_ns_per_sample * samples.len() as u64).div_ceil(1000);
        Timer::after_micros(compute_us).await;
        let now = Instant::now().as_micros();
        let deadline = self.half_start_us(self.next_half);
        let mut result = Ok(());
        if now > deadline {
            // The DAC reached these halves before they were written and
            // replayed what their buffers held.
            let halves = ((now - deadline) / self.half_us() + 1) as u32;
            let mut rec = self.recording.borrow_mut();
            let at = rec.samples.len();
            rec.underruns.push((at, halves));
            for h in self.next_half..self.next_half + u64::from(halves) {
                let stale = self.buffers[Self::physical(h)].clone();
                rec.samples.extend_from_slice(&stale);
            }
            self.next_half += u64::from(halves);
            result = Err(Underrun { halves });
        } else {
            // The buffer is free once the DAC reads the previous half.
            let free_at = deadline.saturating_sub(self.half_us());
            if now < free_at {
                Timer::at(Instant::from_micros(free_at)).await;
            }
        }
        let h = self.next_half;
        let buffer = &mut self.buffers[Self::physical(h)];
        buffer.clear();
        buffer.extend(samples.iter().copied().take(self.half_len));
        buffer.resize(self.half_len, samples.last().copied().unwrap_or_default());
        self.recording
            .borrow_mut()
            .samples
            .extend_from_slice(buffer);
        self.next_half += 1;
        result
    }
}
