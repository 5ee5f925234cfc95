//! The galvo DAC stream of the STM32F4DISCOVERY: [`Stm32GalvoDac`], the
//! board's `laser_app::galvo::DacStream`.
//!
//! TIM8 is the sample clock (168 MHz timer clock, 100 kHz by default).
//! Each update triggers DAC1 in dual-channel mode (X on PA4, Y on PA5,
//! both on the same edge), whose DMA request (DMA1 stream 5 channel 7)
//! loads the next DHR12RD word, and requests DMA2 stream 1 channel 7
//! (TIM8_UP), which writes the next laser word to GPIOB's BSRR (PB0; DMA1
//! cannot reach the AHB1 GPIOs). Both circular buffers hold two halves of
//! [`HALF_LEN`] samples in main SRAM (`.bss`; the DMA cannot reach the
//! CCM, checked at boot). The streams start together once the loop has
//! primed both halves, so they stay in lockstep (checked at every half).
//!
//! The loop runs on the galvo executor (an interrupt above thread mode:
//! USB and the sequencer cannot delay it); the DMA interrupt
//! (`irq.rs`) counts halves, wakes it, and closes the master laser gate
//! the moment the DMA starts a half the loop has not written. The loop
//! learns of it from the DMA position (NDTR) when it hands over its next
//! half ([`galvo_dma::ring::slot`]). The gate's close hook zeroes every
//! laser word ([`darken_laser_stream`]) before pulling PB0 low, so no
//! queued word can light the laser again.
//!
//! Laser words only set the pin on lit samples and reset it after the last
//! lit one; dark samples write nothing, so an idle galvo leaves PB0 to the
//! gimbal's laser switch. Buffer layout, word packing and the bookkeeping
//! are the pure `galvo-dma` crate (host-tested); `regs.rs` is the register
//! layer. Verified by building only: no board or emulator runs it here.

pub(crate) mod buffers;
mod irq;
mod regs;

use core::future::poll_fn;
use core::sync::atomic::Ordering;
use core::task::Poll;

use cortex_m::peripheral::DWT;
use embassy_stm32::gpio::Flex;
use embassy_stm32::interrupt::typelevel::{Binding, DMA1_STREAM5};
use embassy_stm32::peripherals::{DAC1, DMA1_CH5, DMA2_CH1, PA4, PA5, TIM8};
use embassy_stm32::{Peri, dac, rcc, timer};
use galvo_dma::ring::{Claim, Cursor};
use galvo_dma::timing::{RefillMeter, TimerSetting, timer_setting};
use galvo_dma::words::{LaserTrack, dhr12rd, replays_identically};
use laser_app::galvo::{DacSample, DacStream, Half, RefillTime, Underrun};
use laser_app::laser_gate::LaserGate;

pub use buffers::HALF_LEN;
use buffers::{DAC_WORDS, LASER_WORDS, RING, RING_LEN};
pub use irq::HalfInterrupt;
use irq::{SHARED, pack_timer, unpack_timer};

/// Default sample period, s (until the loop sets its own).
const DEFAULT_PERIOD_S: f64 = 10e-6;
/// DAC code of mid-scale (the output before the first stream).
const MID_CODE: u16 = 2048;

/// The CPU's cycle counter (enabled by `board::init`).
fn cycles() -> u32 {
    DWT::cycle_count()
}

/// The request map and pins `regs.rs` hard-codes, checked against
/// embassy-stm32's chip metadata at compile time: DMA1 stream 5 serves
/// DAC1 channel 1 and DMA2 stream 1 TIM8's update (both request channel 7,
/// checked at boot), PA4/PA5 are DAC1's outputs.
const fn request_map<D, U, X, Y>()
where
    D: dac::Dma<DAC1, dac::Ch1>,
    U: timer::UpDma<TIM8>,
    X: dac::DacPin<DAC1, dac::Ch1>,
    Y: dac::DacPin<DAC1, dac::Ch2>,
{
}
const _: () = request_map::<DMA1_CH5, DMA2_CH1, PA4, PA5>();

/// The peripherals the stream owns (nothing else may touch them).
pub struct GalvoDacPeripherals {
    /// Sample clock.
    pub timer: Peri<'static, TIM8>,
    /// DAC1, both channels.
    pub dac: Peri<'static, DAC1>,
    /// DAC stream (DMA1 stream 5).
    pub dac_dma: Peri<'static, DMA1_CH5>,
    /// Laser stream (DMA2 stream 1).
    pub laser_dma: Peri<'static, DMA2_CH1>,
    /// DAC1 channel 1 output, X.
    pub x: Peri<'static, PA4>,
    /// DAC1 channel 2 output, Y.
    pub y: Peri<'static, PA5>,
}

/// The timer-triggered two-channel DAC with its laser stream.
pub struct Stm32GalvoDac {
    gate: &'static LaserGate,
    track: LaserTrack,
    /// Which half is written next; whether the streams run.
    cursor: Cursor,
    /// What each physical half replays identically, with its clock.
    contents: [Option<(DacSample, TimerSetting)>; 2],
    /// Sample clock for the halves written from now on.
    timer: TimerSetting,
    timer_hz: u32,
    cpu_hz: u32,
    meter: RefillMeter,
    _outputs: [Flex<'static>; 2],
    _owned: (
        Peri<'static, TIM8>,
        Peri<'static, DAC1>,
        Peri<'static, DMA1_CH5>,
        Peri<'static, DMA2_CH1>,
    ),
}

impl Stm32GalvoDac {
    /// Sets DAC1 up (both channels on TIM8's trigger, at mid-scale); the
    /// streams start once the loop has written two halves. `cpu_hz` is
    /// the core clock the cycle counter runs at.
    pub fn new(
        p: GalvoDacPeripherals,
        gate: &'static LaserGate,
        laser_pin: u8,
        cpu_hz: u32,
        _irq: impl Binding<DMA1_STREAM5, HalfInterrupt>,
    ) -> Self {
        // DMA cannot reach the CCM: a linker change must not move these.
        defmt::assert!(buffers::in_main_sram());
        defmt::assert!(
            dac::Dma::<DAC1, dac::Ch1>::request(&*p.dac_dma) == regs::REQUEST_CHANNEL
                && timer::UpDma::<TIM8>::request(&*p.laser_dma) == regs::REQUEST_CHANNEL
        );
        rcc::enable_and_reset::<TIM8>();
        rcc::enable_and_reset::<DAC1>();
        let timer_hz = rcc::frequency::<TIM8>().0;
        let mut x = Flex::new(p.x);
        let mut y = Flex::new(p.y);
        x.set_as_analog();
        y.set_as_analog();
        regs::init(dhr12rd(MID_CODE, MID_CODE));
        let timer = timer_setting(timer_hz, DEFAULT_PERIOD_S).unwrap_or(TimerSetting {
            prescaler: 0,
            reload: u16::MAX,
        });
        Self {
            gate,
            track: LaserTrack::new(laser_pin),
            cursor: Cursor::new(),
            contents: [None; 2],
            timer,
            timer_hz,
            cpu_hz,
            meter: RefillMeter::new(),
            _outputs: [x, y],
            _owned: (p.timer, p.dac, p.dac_dma, p.laser_dma),
        }
    }

    /// The half the DMA reads now (NDTR settles a boundary whose
    /// interrupt has not run yet).
    fn reading(&self) -> u32 {
        let counted = SHARED.reading.load(Ordering::Acquire);
        RING.reading_half(counted, regs::dac_ndtr())
            .unwrap_or(counted)
    }

    /// Waits until the cursor's next half may be written; returns the
    /// halves the DMA started before they were written (then the cursor
    /// moved past the half it reads). Returns at once after a fault.
    async fn wait_free(&mut self) -> u32 {
        poll_fn(|cx| {
            SHARED.waker.register(cx.waker());
            if SHARED.fault.load(Ordering::Acquire) {
                return Poll::Ready(0);
            }
            match self.cursor.claim(self.reading()) {
                Claim::Wait => Poll::Pending,
                Claim::Write { late, .. } => Poll::Ready(late),
            }
        })
        .await
    }

    /// Publishes the claimed half as written; `true` when the DMA had
    /// already begun it (the copy ended too late: it began partly stale).
    fn commit(&mut self) -> bool {
        SHARED
            .written
            .store(self.cursor.commit(), Ordering::Release);
        self.cursor.check(self.reading())
    }

    /// Packs `half` into the cursor's next physical half: DAC words,
    /// laser words (lit only while the gate passes the half's
    /// generation), its clock, and whether the ring now holds one sample.
    fn store(&mut self, half: &Half<'_>) {
        let physical = self.cursor.physical();
        // Not a hold while it is being rewritten.
        SHARED.holding.store(false, Ordering::Release);
        let passes = self.gate.passes(true, half.generation);
        let (mut dac, mut laser) = ([0u32; HALF_LEN], [0u32; HALF_LEN]);
        let samples = half.samples.iter().map(|s| (s.x_code, s.y_code, s.laser));
        self.track
            .pack(half.generation, passes, samples, &mut dac, &mut laser);
        for (i, (d, l)) in RING.range(physical).zip(dac.iter().zip(&laser)) {
            DAC_WORDS.store(i, *d);
            LASER_WORDS.store(i, *l);
        }
        if passes && !self.gate.passes(true, half.generation) {
            // Closed meanwhile: its hook darkened what was stored before.
            RING.range(physical).for_each(|i| LASER_WORDS.store(i, 0));
            self.track.darken();
        }
        SHARED.timers[physical].store(pack_timer(self.timer), Ordering::Relaxed);
        // Replays identically only when every word is the same.
        let first = half.samples.first().copied();
        let uniform = half.samples.len() == HALF_LEN
            && half.samples.iter().all(|s| Some(*s) == first)
            && replays_identically(&dac, &laser);
        self.contents[physical] = first.filter(|_| uniform).map(|s| (s, self.timer));
        let holding = self.contents[physical].is_some() && self.contents[0] == self.contents[1];
        SHARED.holding.store(holding, Ordering::Release);
    }

    /// Both halves are primed: start the streams.
    fn start(&mut self) {
        SHARED.reading.store(0, Ordering::Release);
        SHARED.written.store(2, Ordering::Release);
        SHARED.running.store(true, Ordering::Release);
        let timer = unpack_timer(SHARED.timers[0].load(Ordering::Relaxed));
        regs::start(
            DAC_WORDS.address(),
            LASER_WORDS.address(),
            RING_LEN as u16,
            DAC_WORDS.load(0),
            timer,
        );
    }

    /// After a fault (the interrupt stopped the streams): prime again.
    fn reset(&mut self) {
        regs::stop();
        SHARED.running.store(false, Ordering::Release);
        SHARED.holding.store(false, Ordering::Release);
        self.cursor.reset();
        self.contents = [None; 2];
        self.track.darken();
    }
}

impl DacStream for Stm32GalvoDac {
    /// Bisection jump planning (`planner seed`) takes 1.6–7.5 M
    /// instructions per axis here (bench-m4): refused.
    const F64_PLANNING: bool = false;

    fn half_len(&self) -> usize {
        HALF_LEN
    }

    fn set_sample_period(&mut self, period_s: f64) {
        match timer_setting(self.timer_hz, period_s) {
            Some(timer) => self.timer = timer,
            None => defmt::warn!("galvo: sample period refused by TIM8"),
        }
    }

    fn holds(&self, sample: DacSample) -> bool {
        self.cursor.started()
            && !SHARED.fault.load(Ordering::Acquire)
            && self
                .contents
                .iter()
                .all(|c| *c == Some((sample, self.timer)))
    }

    async fn write_half(&mut self, half: Half<'_>) -> Result<(), Underrun> {
        let entered = cycles();
        let mut late = 0;
        if self.cursor.started() {
            late = self.wait_free().await;
        }
        if SHARED.fault.swap(false, Ordering::AcqRel) {
            // The interrupt stopped the streams: what played was dark.
            self.reset();
            late += 1;
        }
        let copy_from = cycles();
        self.store(&half);
        if self.cursor.started() {
            late += u32::from(self.commit());
        } else if self.cursor.primed() {
            self.start();
        }
        self.meter.record(entered, copy_from, cycles());
        if late > 0 {
            Err(Underrun { halves: late })
        } else {
            Ok(())
        }
    }

    async fn repeat_half(&mut self) {
        if !self.cursor.started() {
            return;
        }
        let entered = cycles();
        // However late: both halves hold the sample the loop wants.
        self.wait_free().await;
        if SHARED.fault.load(Ordering::Acquire) {
            // The next write_half restarts the streams and reports it.
            return;
        }
        // A hold replays identically: late or not, nothing to report.
        self.commit();
        let now = cycles();
        self.meter.record(entered, now, now);
    }

    fn worst_refill(&self) -> Option<RefillTime> {
        let window =
            HALF_LEN as u64 * u64::from(self.timer.period_ticks()) * u64::from(self.cpu_hz)
                / u64::from(self.timer_hz.max(1));
        self.meter.worst().map(|cycles| RefillTime {
            cycles,
            cpu_hz: self.cpu_hz,
            window_cycles: u32::try_from(window).unwrap_or(u32::MAX),
        })
    }
}
