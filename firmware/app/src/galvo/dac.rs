//! The DAC side of the galvo loop: one sample, a half buffer, the
//! hardware-timed double-buffered [`DacStream`] a board provides, and what
//! it reports (an underrun, a measured refill time).

use super::cost::LoopWork;

/// One DAC sample: both 12-bit codes and the laser enable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DacSample {
    /// X mirror DAC code, 0..=4095.
    pub x_code: u16,
    /// Y mirror DAC code, 0..=4095.
    pub y_code: u16,
    /// Laser on during this sample.
    pub laser: bool,
}

/// The loop missed a refill deadline: the DAC replayed `halves` stale half
/// buffers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Underrun {
    /// Half buffers replayed.
    pub halves: u32,
}

/// One half buffer handed to the DAC.
#[derive(Debug, Clone, Copy)]
pub struct Half<'a> {
    /// The samples (`half_len` of them).
    pub samples: &'a [DacSample],
    /// [`LaserGate`](crate::laser_gate::LaserGate) generation the samples
    /// were computed under: their laser bits shine only while the gate is
    /// open at this generation (a half computed before a stop stays dark).
    pub generation: u32,
    /// Samples the loop actually computed; the rest repeat a hold sample
    /// (the simulated DAC charges loop time per computed sample).
    pub computed: usize,
    /// What computing the half (and preparing steps before it) took, for
    /// the simulated DAC's M4 cost model ([`M4_COST`](super::M4_COST)).
    pub work: LoopWork,
}

/// A hardware-timed DAC fed from a double buffer: a timer-triggered DMA
/// on the target, a simulated DAC with the same deadlines on the host.
///
/// The DAC's laser output is the samples' laser bit AND the master
/// [`LaserGate`](crate::laser_gate::LaserGate) at the half's generation;
/// a half the DAC replays because the loop was late is output dark.
#[allow(async_fn_in_trait)]
pub trait DacStream {
    /// Whether the CPU that runs the loop on this board plans jumps in
    /// `f64` in time: the patent's bisection (`planner seed`) and the
    /// `f64` fallback of the time-optimal planner. Not on the M4F (the
    /// default): its FPU is single precision, bisection takes 1.6–7.5 M
    /// instructions per axis (bench-m4's `plan.seed.*`, 9–46× the 1.28 ms
    /// refill window), so `planner seed` is refused with a clear error,
    /// jumps are planned time-optimal in `f32` only, and the `f64`
    /// planners are not linked into the image.
    const F64_PLANNING: bool = false;

    /// Samples per half buffer.
    fn half_len(&self) -> usize;

    /// Sets the sample period (s) for the halves written from now on.
    fn set_sample_period(&mut self, period_s: f64);

    /// Whether both halves already hold nothing but `sample` (then
    /// [`Self::repeat_half`] outputs the same as writing it again).
    fn holds(&self, sample: DacSample) -> bool;

    /// Waits until the half the DAC is not reading is free, then stores
    /// `half` in it. `Err` when the DAC had already started on that half
    /// (the loop was late): it replayed that half dark and outputs these
    /// samples one half late.
    async fn write_half(&mut self, half: Half<'_>) -> Result<(), Underrun>;

    /// Waits like [`Self::write_half`] but leaves the next half as the
    /// DAC holds it. Only when [`Self::holds`] the same sample: replaying
    /// an identical hold is the intended output, so this is never an
    /// underrun, however late.
    async fn repeat_half(&mut self);

    /// The worst refill so far as the board measured it (the target
    /// times it with the CPU's cycle counter); `None` where nothing
    /// measures it (the simulator charges modelled costs instead).
    fn worst_refill(&self) -> Option<RefillTime> {
        None
    }
}

/// A refill time measured in CPU cycles (`galvo status`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RefillTime {
    /// CPU cycles of the worst refill (the loop computing a half plus
    /// copying it into the DMA buffer, its wait for the free half not
    /// counted).
    pub cycles: u32,
    /// CPU clock, Hz.
    pub cpu_hz: u32,
    /// CPU cycles one half buffer lasts at the current sample period:
    /// the refill's window.
    pub window_cycles: u32,
}
