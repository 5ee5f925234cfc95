//! The galvo DAC stream (feature `galvo-dac`): a timer interrupt consumes
//! the double buffer at the sample rate, as the STM32's timer-triggered DMA
//! does, so the galvo loop's refill deadline is met (or missed) by the real
//! executor and interrupts at the M4's instruction timing, with the other
//! tasks running. The "DAC output" is the sample register the interrupt
//! sets; the galvo laser's switches are reported on the log channel
//! (`@galvo-laser 0|1`), underruns counted for `galvo status`, and the
//! worst refill measured with the STM32 stream's meter (`galvo-dma`) in
//! instructions (board time under `-icount shift=0`: 1 ns each), shown by
//! `galvo status` as cycles of a 1 GHz clock.
//!
//! Timing: CMSDK dual timer 1 (0x4000_2000, IRQ 10), periodic, at the
//! sample period in 25 MHz ticks.

use core::cell::RefCell;
use core::future::poll_fn;
use core::task::Poll;

use critical_section::Mutex;
use embassy_sync::waitqueue::WakerRegistration;
use galvo_dma::timing::RefillMeter;
use laser_app::galvo::{DacSample, DacStream, Half, RefillTime, Underrun};

use crate::log_channel;
use crate::mmio::Reg;
use crate::parts::LASER_GATE;

/// Samples per half buffer (as the simulator's: 1.28 ms at 100 kHz).
pub const HALF_LEN: usize = 128;
/// Timer ticks per second.
const TIMER_HZ: f64 = 25_000_000.0;
/// Fewest timer ticks per sample (1 MHz).
const MIN_PERIOD_TICKS: u32 = 25;
/// Instructions per timer tick under `-icount shift=0` (1 ns each).
const INSTRUCTIONS_PER_TICK: u64 = 40;
/// The "CPU clock" refill times are given in: one instruction per ns.
const INSTRUCTIONS_HZ: u32 = 1_000_000_000;

/// Instructions since boot (wrapping), for the refill meter.
fn instructions() -> u32 {
    (crate::time_driver::timer_ticks() * INSTRUCTIONS_PER_TICK) as u32
}

const BASE: usize = 0x4000_2000;
const LOAD: Reg = Reg(BASE);
const CONTROL: Reg = Reg(BASE + 0x08);
const INTCLR: Reg = Reg(BASE + 0x0C);
/// CONTROL: enable | periodic | interrupt | 32-bit counter.
const RUN: u32 = (1 << 7) | (1 << 6) | (1 << 5) | (1 << 1);

struct Shared {
    halves: [[DacSample; HALF_LEN]; 2],
    generation: [u32; 2],
    /// The half being output.
    reading: usize,
    /// Next sample of it.
    pos: usize,
    /// The other half holds samples not output yet.
    fresh: bool,
    /// Halves replayed stale since the last write.
    stale: u32,
    /// A half replayed stale outputs dark (until it is written again).
    dark: [bool; 2],
    running: bool,
    /// What the output holds now.
    output: DacSample,
    waker: WakerRegistration,
}

static SHARED: Mutex<RefCell<Shared>> = Mutex::new(RefCell::new(Shared {
    halves: [[DacSample {
        x_code: 2048,
        y_code: 2048,
        laser: false,
    }; HALF_LEN]; 2],
    generation: [0; 2],
    reading: 0,
    pos: 0,
    fresh: false,
    stale: 0,
    dark: [false; 2],
    running: false,
    output: DacSample {
        x_code: 2048,
        y_code: 2048,
        laser: false,
    },
    waker: WakerRegistration::new(),
}));

/// The stream the galvo loop writes.
pub struct QemuDac {
    period_ticks: u32,
    primed: usize,
    meter: RefillMeter,
}

impl QemuDac {
    /// The stream, stopped until both halves are written.
    pub fn new() -> Self {
        crate::interrupts::enable(crate::interrupts::Irq::DualTimer);
        Self {
            period_ticks: 250,
            primed: 0,
            meter: RefillMeter::new(),
        }
    }

    fn store(s: &mut Shared, index: usize, half: &Half<'_>) {
        for (slot, sample) in s.halves[index].iter_mut().zip(half.samples) {
            *slot = *sample;
        }
        s.generation[index] = half.generation;
        s.dark[index] = false;
    }

    fn start(&self) {
        CONTROL.write(0);
        LOAD.write(self.period_ticks);
        INTCLR.write(1);
        CONTROL.write(RUN);
    }
}

impl DacStream for QemuDac {
    fn half_len(&self) -> usize {
        HALF_LEN
    }

    fn set_sample_period(&mut self, period_s: f64) {
        if period_s.is_finite() && period_s > 0.0 {
            // + 0.5 and truncation: round to the nearest tick (no libm).
            let ticks = (period_s * TIMER_HZ + 0.5).clamp(f64::from(MIN_PERIOD_TICKS), 1e9);
            self.period_ticks = ticks as u32;
            if critical_section::with(|cs| SHARED.borrow(cs).borrow().running) {
                LOAD.write(self.period_ticks);
            }
        }
    }

    fn holds(&self, sample: DacSample) -> bool {
        critical_section::with(|cs| {
            let s = SHARED.borrow(cs).borrow();
            s.running && s.halves.iter().flatten().all(|x| *x == sample)
        })
    }

    async fn write_half(&mut self, half: Half<'_>) -> Result<(), Underrun> {
        let entered = instructions();
        let written = self.store_half(half).await;
        let now = instructions();
        // The copy is part of the wait here (done in the same critical
        // section that finds the half free): the refill is the loop's own
        // time between hand-overs.
        self.meter.record(entered, now, now);
        written
    }

    async fn repeat_half(&mut self) {
        let entered = instructions();
        self.repeat().await;
        let now = instructions();
        self.meter.record(entered, now, now);
    }

    fn worst_refill(&self) -> Option<RefillTime> {
        let window = HALF_LEN as u64 * u64::from(self.period_ticks) * INSTRUCTIONS_PER_TICK;
        self.meter.worst().map(|cycles| RefillTime {
            cycles,
            cpu_hz: INSTRUCTIONS_HZ,
            window_cycles: u32::try_from(window).unwrap_or(u32::MAX),
        })
    }
}

impl QemuDac {
    /// Stores `half` in the free half (priming first), as
    /// [`DacStream::write_half`].
    async fn store_half(&mut self, half: Half<'_>) -> Result<(), Underrun> {
        if self.primed < 2 {
            let index = self.primed;
            self.primed += 1;
            let start = critical_section::with(|cs| {
                let mut s = SHARED.borrow(cs).borrow_mut();
                Self::store(&mut s, index, &half);
                if self.primed == 2 {
                    s.reading = 0;
                    s.pos = 0;
                    s.fresh = true;
                    s.running = true;
                }
                s.running
            });
            if start {
                self.start();
            }
            return Ok(());
        }
        poll_fn(|cx| {
            critical_section::with(|cs| {
                let mut s = SHARED.borrow(cs).borrow_mut();
                if s.stale > 0 {
                    // Late: the interrupt replayed the half dark; these
                    // samples go out one half late.
                    let halves = s.stale;
                    s.stale = 0;
                    let next = 1 - s.reading;
                    Self::store(&mut s, next, &half);
                    s.fresh = true;
                    return Poll::Ready(Err(Underrun { halves }));
                }
                if s.fresh {
                    s.waker.register(cx.waker());
                    return Poll::Pending;
                }
                let next = 1 - s.reading;
                Self::store(&mut s, next, &half);
                s.fresh = true;
                Poll::Ready(Ok(()))
            })
        })
        .await
    }

    /// Waits for the free half and keeps it as it is, as
    /// [`DacStream::repeat_half`].
    async fn repeat(&mut self) {
        poll_fn(|cx| {
            critical_section::with(|cs| {
                let mut s = SHARED.borrow(cs).borrow_mut();
                if !s.running {
                    return Poll::Ready(());
                }
                if s.fresh && s.stale == 0 {
                    s.waker.register(cx.waker());
                    return Poll::Pending;
                }
                // The held half is the intended output: never late.
                let next = 1 - s.reading;
                s.stale = 0;
                s.dark[next] = false;
                s.fresh = true;
                Poll::Ready(())
            })
        })
        .await
    }
}

/// One sample period passed: output the next sample; at the end of a half
/// switch to the other, replaying it dark when it was not refilled.
pub unsafe extern "C" fn dual_timer() {
    INTCLR.write(1);
    let laser_changed = critical_section::with(|cs| {
        let mut s = SHARED.borrow(cs).borrow_mut();
        let reading = s.reading;
        let mut sample = s.halves[reading][s.pos];
        sample.laser =
            sample.laser && !s.dark[reading] && LASER_GATE.passes(true, s.generation[reading]);
        let was = s.output.laser;
        s.output = sample;
        s.pos += 1;
        if s.pos == HALF_LEN {
            s.pos = 0;
            s.reading = 1 - reading;
            if s.fresh {
                s.fresh = false;
            } else {
                s.stale += 1;
                s.dark[1 - reading] = true;
            }
            s.waker.wake();
        }
        (was != sample.laser).then_some(sample.laser)
    });
    if let Some(lit) = laser_changed {
        log_channel::line(format_args!("@galvo-laser {}", u8::from(lit)));
    }
}
