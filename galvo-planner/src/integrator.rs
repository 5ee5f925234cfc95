//! The per-sample state-update integrator: what the galvo loop calls every
//! sample (or once per DMA block).
//!
//! A [`Integrator`] owns one axis's commanded state and a ring of queued input
//! voltages. Every sample it advances
//! `Z(k+1) = Z(k) + ((Ad − I)·Z(k) + Bd·U(k))` in `f32` and yields the
//! commanded motor angle θ. When a move's last sample is reached the state
//! snaps to the move's exact planned target, so `f32` rounding never
//! accumulates from one move to the next; when no move is queued it holds
//! the last position without integrating.
//!
//! ## Per-sample cost
//!
//! The Cortex-M4F FPU is single precision only, so the update is `f32`
//! with the model stored as `Ad − I` (the increment form keeps the
//! near-one diagonal of `Ad` from losing the small rates in rounding) and a
//! compensated (Kahan) accumulation of the state. Per sample and axis:
//! each state row costs `1 + S` multiplies and `S` adds for
//! `(Ad − I)·Z + Bd·U` and 4 add/subs for the compensated sum, i.e.
//! **rigid (S = 3): 12 mul + 9 add + 12 add = 33 flops; flexible (S = 5):
//! 30 + 25 + 20 = 75 flops**, plus a ring-buffer read and a counter
//! compare. The rigid model runs as fixed multiply-adds (`advance3`:
//! the loop builds this crate's generics for size, which keeps loops as
//! loops). Measured on the M4F ISA (`cargo xtask bench-m4`): 204
//! instructions per sample for both axes while moving (was 560 with the
//! generic loops), ≈ 1.6 µs at 168 MHz and CPI 1.3.
//!
//! Accuracy (tests): over ±10° moves the `f32` angle stays within 2e-8 rad
//! (about one `f32` ulp) of the `f64` ZOH simulation at Ts = 10 µs and 1 µs;
//! without the compensated sum the error reaches 7e-7 rad at Ts = 1 µs.
//!
//! ## Queueing
//!
//! Moves are appended with [`Integrator::queue`] while one runs; each must start
//! at the state where the previously queued one ends
//! ([`Integrator::end_state`]). Capacity is fixed at compile time: `CAP` input
//! samples in the ring and `Q` moves.

mod axis;
mod xy;

pub use axis::Integrator;
pub use xy::XyIntegrator;

#[cfg(test)]
mod tests;
