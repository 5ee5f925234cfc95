//! The project's hot paths on the Cortex-M4F instruction set.
//!
//! Runs on QEMU's `mps2-an386` (Cortex-M4F) under `-icount shift=0`, where
//! the virtual clock advances exactly 1 ns per guest instruction. The
//! CMSDK APB timer 0 counts down at 25 MHz, so one timer tick is 40
//! instructions; every run first calibrates that ratio on an assembly loop
//! of known length. Each benchmark reads the timer around a window of many
//! repetitions and prints one line
//!
//! `bench <id> <ticks> <units>`
//!
//! (`units` = repetitions in the window: samples, halves or calls); `cargo
//! xtask bench-m4` turns the ticks into instructions and µs, checks the
//! budgets and writes the JSON table. Output and exit code go through ARM
//! semihosting.
//!
//! The crates are linked exactly as the firmware builds them: release
//! profile (the math crates at opt-level 3, the rest for size), FPU on.

#![no_std]
#![no_main]

use core::fmt::Write;
use core::hint::black_box;

use cortex_m_rt::entry;

mod checks;
mod galvo_loop;
mod gcode;
mod harness;
mod kinematics;
mod path;
mod pelco;
mod planning;
mod semihosting;
mod stepper;
mod sweep;
mod sweep_strokes;
mod timer;

use harness::{Bench, calibration_loop, window};
use semihosting::Out;

/// Iterations of the calibration loop (2 instructions each).
const CALIBRATION_ITERATIONS: u32 = 1_000_000;

#[entry]
fn main() -> ! {
    timer::start();
    let mut b = Bench::new();
    let _ = writeln!(b.out, "bench-m4 1");
    b.out.flush();

    // Calibration: a loop of known length, and the empty window.
    let ticks = window(|| calibration_loop(black_box(CALIBRATION_ITERATIONS)));
    let _ = writeln!(
        b.out,
        "calibration {} {ticks}",
        2 * u64::from(CALIBRATION_ITERATIONS)
    );
    let empty = (0..64).map(|_| window(|| ())).sum::<u32>();
    let _ = writeln!(b.out, "empty {empty} 64");
    b.out.flush();

    checks::self_checks(&mut b);
    kinematics::kinematics(&mut b);
    path::integrator_and_path(&mut b);
    galvo_loop::loop_halves(&mut b);
    planning::planning(&mut b);
    stepper::stepper(&mut b);
    sweep::jump_sweep(&mut b);
    sweep_strokes::stroke_sweep(&mut b);
    pelco::pelco(&mut b);
    gcode::gcode_lines(&mut b);

    let _ = writeln!(b.out, "done {}", b.failures);
    b.out.flush();
    semihosting::exit(b.failures == 0)
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    let mut out = Out::new();
    let _ = writeln!(out, "panic");
    out.flush();
    semihosting::exit(false)
}
