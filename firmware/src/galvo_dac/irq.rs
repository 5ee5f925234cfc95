//! The DAC stream's interrupt (DMA1 stream 5, half transfer and transfer
//! complete): counts the halves the DMA starts, applies each half's sample
//! clock, cuts the laser when the DMA starts a half the refill has not
//! written, checks the laser stream is still in lockstep, and wakes the
//! refill. It runs at the DMA interrupts' priority (embassy's P0), above
//! the galvo executor, so its count is never more than microseconds late.

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use embassy_stm32::interrupt::typelevel::{DMA1_STREAM5, Handler};
use embassy_sync::waitqueue::AtomicWaker;
use galvo_dma::ring::{Ring, underrun_at_start};
use galvo_dma::timing::TimerSetting;

use super::buffers::RING;
use super::regs;
use crate::laser_gate::LASER_GATE;

/// State shared by the refill (the galvo task) and the interrupt.
pub(super) struct Shared {
    /// The half the DMA reads, as the interrupt last counted it.
    pub reading: AtomicU32,
    /// Halves below this are in the buffer (the refill's progress).
    pub written: AtomicU32,
    /// Both halves hold one identical sample: replaying them is intended.
    pub holding: AtomicBool,
    /// The streams run.
    pub running: AtomicBool,
    /// The interrupt stopped the streams on an error (taken by the refill).
    pub fault: AtomicBool,
    /// Each physical half's sample clock ([`pack_timer`]).
    pub timers: [AtomicU32; 2],
    /// The refill waiting for a half to come free.
    pub waker: AtomicWaker,
}

pub(super) static SHARED: Shared = Shared {
    reading: AtomicU32::new(0),
    written: AtomicU32::new(0),
    holding: AtomicBool::new(false),
    running: AtomicBool::new(false),
    fault: AtomicBool::new(false),
    timers: [AtomicU32::new(0), AtomicU32::new(0)],
    waker: AtomicWaker::new(),
};

/// A timer setting in one word (prescaler high, reload low).
pub(super) fn pack_timer(timer: TimerSetting) -> u32 {
    u32::from(timer.prescaler) << 16 | u32::from(timer.reload)
}

pub(super) fn unpack_timer(word: u32) -> TimerSetting {
    TimerSetting {
        prescaler: (word >> 16) as u16,
        reload: word as u16,
    }
}

/// The handler bound to `DMA1_STREAM5` (`board.rs`).
pub struct HalfInterrupt;

impl Handler<DMA1_STREAM5> for HalfInterrupt {
    unsafe fn on_interrupt() {
        on_half_boundary();
    }
}

fn on_half_boundary() {
    let events = regs::take_events();
    if let Some(why) = events.error {
        fault(why);
        return;
    }
    if events.boundaries == 0 || !SHARED.running.load(Ordering::Acquire) {
        return;
    }
    let mut started = SHARED.reading.load(Ordering::Relaxed);
    for _ in 0..events.boundaries {
        started = started.wrapping_add(1);
        let written = SHARED.written.load(Ordering::Acquire);
        let holding = SHARED.holding.load(Ordering::Acquire);
        if underrun_at_start(started, written, holding) {
            // Stale content is playing: dark now (the refill reports it).
            LASER_GATE.close();
        }
    }
    SHARED.reading.store(started, Ordering::Release);
    // The half's own sample clock, preloaded: it takes effect at the next
    // update, which outputs the previous half's last sample (the DAC's
    // one-update delay), so a period change starts one sample early.
    let timer = SHARED.timers[Ring::physical(started)].load(Ordering::Relaxed);
    regs::set_timer(unpack_timer(timer));
    if !RING.in_lockstep(regs::dac_ndtr(), regs::laser_ndtr()) {
        fault("laser stream out of lockstep");
        return;
    }
    SHARED.waker.wake();
}

/// Stops both streams (the laser stream can no longer be trusted to sit
/// on the DAC's samples), closes the gate, and lets the refill restart.
pub(super) fn fault(why: &'static str) {
    regs::stop();
    SHARED.running.store(false, Ordering::Release);
    SHARED.fault.store(true, Ordering::Release);
    LASER_GATE.close();
    defmt::error!("galvo DAC stopped: {}; laser off", why);
    SHARED.waker.wake();
}
