//! laser-app's logs as defmt (feature `defmt-log`): rzcobs-framed defmt
//! frames on UART3 (0x4000_7000, written by polling, no interrupt), stamped
//! with the board's time in µs, decoded on the host by `cargo xtask qemu`
//! with `defmt-decoder` against this image's ELF, so they read as with
//! probe-rs. The laser/LED/event reports stay plain-text records on UART2
//! (`log_channel`): the host parses those, and they cost no format table.
//!
//! A frame is written inside one critical section (acquire → release), so
//! frames from tasks, interrupt handlers and fault handlers never mix.

use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicBool, Ordering};

use crate::uart::UART3;

#[defmt::global_logger]
struct UartLogger;

/// The frame encoder and the critical section a frame holds.
struct FrameState {
    encoder: defmt::Encoder,
    restore: critical_section::RestoreState,
}

/// Only touched between `acquire` and `release`, inside the critical
/// section `acquire` entered (one core): never shared.
struct FrameCell(UnsafeCell<FrameState>);

// SAFETY: accessed only inside the critical section (see `FrameCell`).
unsafe impl Sync for FrameCell {}

static FRAME: FrameCell = FrameCell(UnsafeCell::new(FrameState {
    encoder: defmt::Encoder::new(),
    restore: critical_section::RestoreState::invalid(),
}));
/// A frame is open.
static TAKEN: AtomicBool = AtomicBool::new(false);
/// A frame was started while one was open (only from a fault handler
/// interrupting a frame): that inner frame is dropped whole.
static NESTED: AtomicBool = AtomicBool::new(false);

fn send(bytes: &[u8]) {
    for &b in bytes {
        UART3.write_blocking(b);
    }
}

// SAFETY: `acquire`/`release` bracket every frame inside a critical
// section; `write`/`flush` run only between them (defmt's contract).
unsafe impl defmt::Logger for UartLogger {
    fn acquire() {
        // SAFETY: released in `release` (or here on a nested acquire).
        let restore = unsafe { critical_section::acquire() };
        if TAKEN.swap(true, Ordering::Relaxed) {
            NESTED.store(true, Ordering::Relaxed);
            // SAFETY: the acquire just above.
            unsafe { critical_section::release(restore) };
            return;
        }
        // SAFETY: inside the critical section, frame not open elsewhere.
        let state = unsafe { &mut *FRAME.0.get() };
        state.restore = restore;
        state.encoder.start_frame(send);
    }

    unsafe fn flush() {}

    unsafe fn release() {
        if NESTED.swap(false, Ordering::Relaxed) {
            return;
        }
        // SAFETY: `acquire` opened the frame in this critical section.
        let state = unsafe { &mut *FRAME.0.get() };
        state.encoder.end_frame(send);
        let restore = state.restore;
        TAKEN.store(false, Ordering::Relaxed);
        // SAFETY: the state `acquire` saved.
        unsafe { critical_section::release(restore) };
    }

    unsafe fn write(bytes: &[u8]) {
        if NESTED.load(Ordering::Relaxed) {
            return;
        }
        // SAFETY: between `acquire` and `release`.
        let state = unsafe { &mut *FRAME.0.get() };
        state.encoder.write(bytes, send);
    }
}

defmt::timestamp!("{=u64:us}", embassy_time::Instant::now().as_micros());

/// Enables UART3's transmitter.
pub fn init() {
    UART3.enable_tx();
}
