//! What a half buffer cost the galvo loop on the Cortex-M4F: the loop
//! counts its work per half ([`LoopWork`]: samples per phase, steps
//! started and prepared, rebuilds), and [`M4_COST`] turns that into
//! target time. The simulated DAC charges it before the half's deadline,
//! so a pattern that would underrun on the board underruns in the
//! simulator too.
//!
//! The constants are M4 instruction counts from `cargo xtask bench-m4`
//! (QEMU mps2-an386, `-icount`: exact guest instructions of the release
//! build), each named after the bench row it comes from; time at CPI 1.3
//! and 168 MHz like the bench's. The test
//! `tests/tests/galvo_cost.rs` checks them against the bench's JSON table
//! when a run left one (`target/bench-m4.json`). Not modelled: flash wait
//! states, VDIV/VSQRT latency, interrupts (as the bench). A jump planned
//! by the patent's bisection (`planner seed`, which the simulator allows
//! for comparison and the STM32 refuses) is charged per axis at the
//! cheapest bench row, `plan.seed.0.1deg` (1.57 M instructions, 12 ms):
//! a lower bound 9× the 1.28 ms refill window, so a seed-planned pattern
//! underruns in the simulator as it would on the board.

/// Work the loop did for one half buffer (and the prep before it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LoopWork {
    /// Refills (0 when the DAC replays a hold, else 1).
    pub refills: u32,
    /// Samples copied from one held sample (settling, dwell, delays, idle).
    pub held: u32,
    /// Jump samples copied from codes the prep stage computed.
    pub jump_copied: u32,
    /// Jump samples stepped on the integrator (jumps too long to prepare).
    pub jump_stepped: u32,
    /// Marking and braking samples (path sampler + galvo IK + DAC).
    pub marked: u32,
    /// Steps started (a jump queued, its codes taken over).
    pub steps_started: u32,
    /// Point steps prepared (IK, jump plan, jump codes).
    pub points_prepared: u32,
    /// Stroke steps prepared (point step + the stroke's f64 set-up).
    pub strokes_prepared: u32,
    /// Axes of prepared jumps planned by bisection (`planner seed`), on
    /// top of their step's cost.
    pub bisection_axes: u32,
    /// Loops rebuilt for new parameters, mirror model kept.
    pub rebuilds: u32,
    /// Loops rebuilt with a new mirror model (sampled again, `f64`).
    pub models_sampled: u32,
}

/// M4 instructions per unit of [`LoopWork`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostModel {
    /// Per refill, fixed.
    pub refill: u64,
    /// Per held sample.
    pub held: u64,
    /// Per copied jump sample.
    pub jump_copied: u64,
    /// Per stepped jump sample.
    pub jump_stepped: u64,
    /// Per marking or braking sample.
    pub marked: u64,
    /// Per started step.
    pub step_started: u64,
    /// Per prepared point step.
    pub point_prepared: u64,
    /// Per prepared stroke step.
    pub stroke_prepared: u64,
    /// Per axis of a jump planned by bisection.
    pub bisection_axis: u64,
    /// Per rebuild, mirror model kept.
    pub rebuild: u64,
    /// Per rebuild with a new mirror model.
    pub model_sampled: u64,
    /// Cycles per instruction.
    pub cpi: f64,
    /// Core clock, Hz.
    pub clock_hz: f64,
}

/// The STM32F407's loop, fitted to `cargo xtask bench-m4` (each field's
/// source row below; see the module doc).
pub const M4_COST: CostModel = CostModel {
    // `loop.holding.refill` (a whole holding half: 1 680) less its 128
    // held samples.
    refill: 1_680 - 128 * 10,
    // `loop.holding.refill` / 128, rounded down (the rest is `refill`).
    held: 10,
    // `loop.jump.steady`.
    jump_copied: 32,
    // `integrator.xy.step` + `galvo.sample_map.angles_to_codes` (200 + 103
    // = 303: kinematics-core built at opt-level "s"), rounded up with a
    // little margin (the bench's counts move by ~1 % with the image).
    jump_stepped: 310,
    // `loop.arc_r40.steady` (236.9, the dearest of the marking rows with
    // `loop.tuning.steady`), rounded up with ~1 % of margin.
    marked: 240,
    // `loop.jump.refill`, the whole half that starts a jump (its samples
    // included: an upper bound; 9 520–9 556 measured as the image around
    // it changes), with ~1 % of margin.
    step_started: 9_640,
    // `loop.jump.prep` (63 040–63 116 measured), with ~0.5 % of margin.
    point_prepared: 63_480,
    // `loop.stroke.prep` (68 280–68 676 as the image around it changes):
    // the dearest stroke step, a jump and a G-code stroke of four lines
    // (its open end needs its own IK), rounded up with ~0.5 % of margin.
    // A G-code piece joined to the stroke being marked (`loop.join.prep`,
    // 24 076) is charged as one.
    stroke_prepared: 69_000,
    // `plan.seed.0.1deg` (1.572 M), rounded up: the cheapest bisection
    // plan, a lower bound for any jump.
    bisection_axis: 1_580_000,
    // `loop.reconfigure`.
    rebuild: 4_560,
    // `loop.new`.
    model_sampled: 371_080,
    cpi: 1.3,
    clock_hz: 168e6,
};

impl CostModel {
    /// M4 instructions of `work`.
    pub fn instructions(&self, work: &LoopWork) -> u64 {
        let n = |count: u32, cost: u64| u64::from(count) * cost;
        n(work.refills, self.refill)
            + n(work.held, self.held)
            + n(work.jump_copied, self.jump_copied)
            + n(work.jump_stepped, self.jump_stepped)
            + n(work.marked, self.marked)
            + n(work.steps_started, self.step_started)
            + n(work.points_prepared, self.point_prepared)
            + n(work.strokes_prepared, self.stroke_prepared)
            + n(work.bisection_axes, self.bisection_axis)
            + n(work.rebuilds, self.rebuild)
            + n(work.models_sampled, self.model_sampled)
    }

    /// Time `work` takes on the target, ns.
    pub fn ns(&self, work: &LoopWork) -> u64 {
        let instructions = self.instructions(work) as f64;
        libm::ceil(instructions * self.cpi / self.clock_hz * 1e9) as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_half_marking_costs_what_the_bench_measured() {
        let marking = LoopWork {
            refills: 1,
            marked: 128,
            ..LoopWork::default()
        };
        // 400 + 128 · 240 instructions at CPI 1.3, 168 MHz: ≈ 241 µs.
        assert_eq!(M4_COST.instructions(&marking), 400 + 128 * 240);
        let ns = M4_COST.ns(&marking);
        assert!((240_000..242_000).contains(&ns), "{ns}");
        // Under half the 1.28 ms window, as the bench's budget says.
        assert!(ns < 640_000);
        assert_eq!(M4_COST.ns(&LoopWork::default()), 0);
    }

    #[test]
    fn a_bisection_jump_overruns_the_refill_window() {
        let seed_jump = LoopWork {
            points_prepared: 1,
            bisection_axes: 2,
            ..LoopWork::default()
        };
        // Two axes at ≥ 1.57 M instructions: ≥ 24 ms, 19× the 1.28 ms window.
        assert!(M4_COST.ns(&seed_jump) > 18 * 1_280_000);
    }
}
