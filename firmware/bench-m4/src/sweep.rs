//! Seeded random sweeps: the dearest input of many, not a chosen one.
//!
//! * `sweep.plan.xy`: [`JUMPS`] two-axis jumps planned as the loop plans
//!   them on the M4F (`plan_xy_jump_f32`): a third anywhere to anywhere
//!   in the DAC's range, a third tiny (1 LSB to ~8 mm, log-uniform, one
//!   or both axes) from anywhere, a third tiny from near the field's edge.
//! * `sweep.stroke.*`: [`STROKES`] G-code-like strokes with close corners
//!   ([`sweep_strokes`](crate::sweep_strokes)).
//!
//! Each sweep prints the worst case as a `bench` line, the median input's
//! figure as `median <id> <ticks> <units>` and the worst input as
//! `worst <id> <inputs tried> <input…>`; `cargo xtask bench-m4` checks the
//! budget on the worst and shows its input. The seed is fixed: every run
//! tries the same inputs, so the figures are reproducible.

use core::fmt::Write;
use core::hint::black_box;

use galvo_planner::plan_xy_jump_f32;
use kinematics_core::Galvo;

use crate::harness::{Bench, CAPACITY, reference_plant_at_10us, window};

/// Two-axis jumps tried.
pub const JUMPS: u32 = 3000;
/// The generator's seed (any non-zero value; fixed for reproducible runs).
pub const SEED: u64 = 0x2545_f491_4f6c_dd1d;

/// xorshift64*: a small, seedable generator (no_std, no allocation).
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed | 1)
    }

    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[a, b)`.
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }

    /// Log-uniform in `[a, b)` (`0 < a < b`).
    pub fn log_range(&mut self, a: f64, b: f64) -> f64 {
        a * libm::exp(self.unit() * libm::log(b / a))
    }

    /// `-1.0` or `1.0`.
    pub fn sign(&mut self) -> f64 {
        if self.next_u64() >> 63 == 0 {
            -1.0
        } else {
            1.0
        }
    }

    /// Uniform in `0..n`.
    pub fn below(&mut self, n: u32) -> u32 {
        (((self.next_u64() >> 32) * u64::from(n)) >> 32) as u32
    }
}

/// Prints the median of `figures` (timer ticks, units), by ticks per
/// unit, as `median <id> <ticks> <units>` (sorts `figures`).
pub fn report_median(b: &mut Bench, id: &str, figures: &mut [(u32, u32)]) {
    figures.sort_unstable_by(|p, q| {
        (u64::from(p.0) * u64::from(q.1)).cmp(&(u64::from(q.0) * u64::from(p.1)))
    });
    if let Some((ticks, units)) = figures.get(figures.len() / 2) {
        let _ = writeln!(b.out, "median {id} {ticks} {units}");
        b.out.flush();
    }
}

/// Highest DAC code (12 bits).
const MAX_CODE: f64 = 4095.0;
/// "Near the edge": within this many codes of 0 or 4095.
const EDGE_CODES: f64 = 40.0;

/// One jump's input in DAC code units (fractional: any angle).
#[derive(Debug, Clone, Copy, Default)]
struct JumpInput {
    from: [f64; 2],
    to: [f64; 2],
}

/// The `i`th jump of the sweep (see the module documentation).
fn jump_input(rng: &mut Rng, i: u32) -> JumpInput {
    let anywhere = |rng: &mut Rng| rng.range(0.0, MAX_CODE);
    match i % 3 {
        0 => JumpInput {
            from: [anywhere(rng), anywhere(rng)],
            to: [anywhere(rng), anywhere(rng)],
        },
        kind => {
            let edge = |rng: &mut Rng| {
                let d = rng.range(0.0, EDGE_CODES);
                if rng.sign() < 0.0 { d } else { MAX_CODE - d }
            };
            let from = if kind == 1 {
                [anywhere(rng), anywhere(rng)]
            } else {
                // One axis or both at the edge.
                match rng.below(3) {
                    0 => [edge(rng), anywhere(rng)],
                    1 => [anywhere(rng), edge(rng)],
                    _ => [edge(rng), edge(rng)],
                }
            };
            // 1 LSB to 100 codes (~8.5 mm), one axis still in a quarter.
            let still = rng.below(4);
            let mut to = from;
            for (axis, t) in to.iter_mut().enumerate() {
                if still == axis as u32 {
                    continue;
                }
                let step = rng.sign() * rng.log_range(1.0, 100.0);
                let moved = *t + step;
                *t = if (0.0..=MAX_CODE).contains(&moved) {
                    moved
                } else {
                    *t - step
                };
            }
            JumpInput { from, to }
        }
    }
}

/// Writes `input` as board mm and DAC codes.
fn describe_jump(out: &mut impl Write, galvo: &Galvo<f64>, j: &JumpInput) {
    let mm = |c: [f64; 2]| {
        let a = kinematics_core::MirrorAngles {
            x_rad: (c[0] - galvo.dac_x.offset_code) / galvo.dac_x.codes_per_rad,
            y_rad: (c[1] - galvo.dac_y.offset_code) / galvo.dac_y.codes_per_rad,
        };
        galvo
            .geometry
            .fk(a)
            .map_or([f64::NAN; 2], |p| [p.x_mm, p.y_mm])
    };
    let (a, b) = (mm(j.from), mm(j.to));
    let _ = write!(
        out,
        "({:.3},{:.3})->({:.3},{:.3}) mm, codes ({:.2},{:.2})->({:.2},{:.2})",
        a[0], a[1], b[0], b[1], j.from[0], j.from[1], j.to[0], j.to[1]
    );
}

/// The two-axis jump sweep: [`JUMPS`] seeded random jumps planned as the
/// loop plans them; reports the dearest (`sweep.plan.xy`) with its input.
/// A jump the `f32` planner cannot plan is an error (the loop would
/// refuse it).
pub fn jump_sweep(b: &mut Bench) {
    let id = "sweep.plan.xy";
    let disc = match reference_plant_at_10us() {
        Ok(d) => d,
        Err(e) => return b.fail(id, e),
    };
    let galvo = Galvo::<f64>::default();
    let rad = |c: [f64; 2]| {
        [
            (c[0] - galvo.dac_x.offset_code) / galvo.dac_x.codes_per_rad,
            (c[1] - galvo.dac_y.offset_code) / galvo.dac_y.codes_per_rad,
        ]
    };
    let mut rng = Rng::new(SEED);
    let mut worst = (0u32, JumpInput::default());
    let mut figures = [(0u32, 1u32); JUMPS as usize];
    let mut planned = 0;
    let mut failed = 0u32;
    for i in 0..JUMPS {
        let input = jump_input(&mut rng, i);
        let (from, to) = (rad(input.from), rad(input.to));
        let mut ok = true;
        let ticks = window(|| {
            ok = plan_xy_jump_f32(&disc, &disc, from, to, CAPACITY)
                .map(|p| {
                    black_box(&p);
                })
                .is_ok();
        });
        if !ok {
            failed += 1;
            let _ = write!(b.out, "error {id} jump {i} not planned: ");
            describe_jump(&mut b.out, &galvo, &input);
            let _ = writeln!(b.out);
            b.out.flush();
        } else {
            if let Some(slot) = figures.get_mut(planned) {
                *slot = (ticks, 1);
                planned += 1;
            }
            if ticks > worst.0 {
                worst = (ticks, input);
            }
        }
    }
    b.failures += failed;
    b.report(id, worst.0, 1);
    report_median(b, id, figures.get_mut(..planned).unwrap_or_default());
    let _ = write!(b.out, "worst {id} {JUMPS} ");
    describe_jump(&mut b.out, &galvo, &worst.1);
    let _ = writeln!(b.out);
    b.out.flush();
}
