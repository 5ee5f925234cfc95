//! The galvo loop's memory ([`GalvoMemory`]): what a board keeps in a
//! `static` so the loop is counted once and never built on a stack.

use super::{GalvoLoop, MAX_HALF_LEN};
use crate::galvo::dac::DacSample;

/// The galvo loop's memory: the loop (its prepared steps and jump
/// integrator, about 22 KB) and the half buffer of `HALF` samples it
/// computes into (at least the DAC's [`DacStream::half_len`](crate::galvo::dac::DacStream::half_len)). A board
/// keeps it in a `static` and hands it to
/// [`GalvoTask::run_in`](crate::app::GalvoTask::run_in), so it is counted
/// once and the task's future holds only a reference.
pub struct GalvoMemory<const HALF: usize = MAX_HALF_LEN> {
    pub(crate) galvo: Option<GalvoLoop>,
    pub(crate) half: [DacSample; HALF],
}

impl<const HALF: usize> GalvoMemory<HALF> {
    const HALF_OK: () = assert!(HALF > 0 && HALF <= MAX_HALF_LEN, "HALF in 1..=512");

    /// No loop yet, a dark half buffer (usable in a `static`).
    pub const fn new() -> Self {
        let () = Self::HALF_OK;
        Self {
            galvo: None,
            half: [DacSample {
                x_code: 0,
                y_code: 0,
                laser: false,
            }; HALF],
        }
    }
}

impl<const HALF: usize> GalvoMemory<HALF> {
    /// [`Self::new`] written into `slot` (a board's `static`, e.g.
    /// `StaticCell::uninit()`) field by field: no 22 KB temporary on the
    /// stack, no 22 KB initialiser in flash.
    #[inline(never)]
    pub fn init_in(slot: &mut core::mem::MaybeUninit<Self>) -> &mut Self {
        let () = Self::HALF_OK;
        let memory = slot.as_mut_ptr();
        // SAFETY: `memory` comes from a `&mut MaybeUninit<Self>`, so it is
        // valid and aligned for `Self`; both fields (the only ones) are
        // written through raw pointers before the value is assumed
        // initialised, and nothing reads them before.
        unsafe {
            core::ptr::addr_of_mut!((*memory).galvo).write(None);
            let half = core::ptr::addr_of_mut!((*memory).half).cast::<DacSample>();
            for i in 0..HALF {
                half.add(i).write(DacSample::default());
            }
            slot.assume_init_mut()
        }
    }
}

impl<const HALF: usize> Default for GalvoMemory<HALF> {
    fn default() -> Self {
        Self::new()
    }
}
