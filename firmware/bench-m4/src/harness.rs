//! The measuring harness: timer windows, the calibration loop, the
//! `bench`/`error` lines, and what several benchmark groups share.

use core::fmt::Write;
use core::hint::black_box;

use galvo_planner::model::RIGID_STATES;
use galvo_planner::{Discrete, RigidParams};

use crate::semihosting::Out;
use crate::timer;

/// Samples per DMA half buffer (1.28 ms at 100 kHz).
pub const HALF: usize = 128;
/// Jump input samples the integrator holds (the loop's `INTEGRATOR_CAPACITY`).
pub const CAPACITY: usize = 1024;

/// Ticks of one window around `f`, with the window's own cost (two timer
/// reads) not removed: xtask subtracts the `empty` window.
#[inline(never)]
pub fn window<R>(f: impl FnOnce() -> R) -> u32 {
    let t0 = timer::now();
    let r = f();
    let t1 = timer::now();
    black_box(r);
    t0.wrapping_sub(t1)
}

/// `2·n` instructions of `subs`/`bne`, plus the window's fixed cost.
#[inline(never)]
pub fn calibration_loop(n: u32) {
    #[cfg(target_arch = "arm")]
    // SAFETY: a register-only countdown loop; touches no memory.
    unsafe {
        core::arch::asm!(
            "2:",
            "subs {n}, {n}, #1",
            "bne 2b",
            n = inout(reg) n => _,
            options(nomem, nostack),
        );
    }
    #[cfg(not(target_arch = "arm"))]
    black_box(n);
}

/// The semihosting output and the count of failed benchmarks.
pub struct Bench {
    pub out: Out,
    pub failures: u32,
}

impl Bench {
    pub fn new() -> Self {
        Self {
            out: Out::new(),
            failures: 0,
        }
    }

    pub fn report(&mut self, id: &str, ticks: u32, units: u32) {
        let _ = writeln!(self.out, "bench {id} {ticks} {units}");
        self.out.flush();
    }

    pub fn fail(&mut self, id: &str, what: impl core::fmt::Debug) {
        self.failures += 1;
        let _ = writeln!(self.out, "error {id} {what:?}");
        self.out.flush();
    }

    /// `units` repetitions of `f` in one window.
    pub fn repeat<R>(&mut self, id: &str, units: u32, mut f: impl FnMut() -> R) {
        let ticks = window(|| {
            for _ in 0..units {
                black_box(f());
            }
        });
        self.report(id, ticks, units);
    }
}

/// Degrees to radians.
pub fn deg(d: f64) -> f64 {
    d * core::f64::consts::PI / 180.0
}

/// The reference rigid galvo model discretized at the 10 µs sample
/// period.
pub fn reference_plant_at_10us() -> Result<Discrete<RIGID_STATES>, galvo_planner::Error> {
    RigidParams::REFERENCE
        .model()
        .and_then(|m| m.discretize(10e-6))
}

/// A short `<prefix><suffix>` id without an allocator.
pub struct Name {
    buf: [u8; 64],
    len: usize,
}

impl Name {
    pub fn new() -> Self {
        Self {
            buf: [0; 64],
            len: 0,
        }
    }

    pub fn set(&mut self, a: &str, b: &str) {
        self.len = 0;
        for &c in a.as_bytes().iter().chain(b.as_bytes()) {
            if let Some(slot) = self.buf.get_mut(self.len) {
                *slot = c;
                self.len += 1;
            }
        }
    }

    pub fn as_str(&self) -> &str {
        self.buf
            .get(..self.len)
            .and_then(|s| core::str::from_utf8(s).ok())
            .unwrap_or("?")
    }
}
