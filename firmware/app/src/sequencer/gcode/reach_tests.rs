//! The soft-limit check's fast path never passes a block the exact check
//! refuses (reach.rs), and it does pass the usual ones.

use crate::domain::Actuator;
use crate::grbl::block::Arc;
use crate::grbl::{Block, Laser, PointMm};
use crate::sequencer::gcode::reach::ReachCheck;
use crate::sequencer::machine::Core;
use crate::settings::find_param;
use embassy_time::Instant;
use proptest::prelude::*;
extern crate std;

/// Settings the proof is tried on: defaults, then geometries where the
/// limits, the DAC range or the board extent cut into the board, and
/// ones the proof does not cover (roll).
const VARIANTS: &[&[(&str, f64)]] = &[
    &[],
    &[("ol_cm", 8.0), ("oq_cm", 12.0)],
    &[("grid.x_offset_cm", 6.0), ("grid.y_offset_cm", -4.0)],
    &[("yaw.min_deg", -15.0), ("yaw.max_deg", 20.0)],
    &[
        ("stepper.pan.max_deg", 14.0),
        ("stepper.tilt.min_deg", -10.0),
    ],
    &[("grid.pitch_cm", 4.0), ("galvo.d_mm", 150.0)],
    &[("grid.pitch_cm", 3.0), ("oq_cm", 15.0), ("ol_cm", 5.0)],
    &[("yaw.min_deg", 60.0), ("pitch.max_deg", 120.0)],
    &[("board.roll_deg", 3.0)],
];
/// The variants whose limits leave half the board or more reachable.
const COVERED: usize = 5;

const ACTUATORS: [Actuator; 4] = [
    Actuator::Gimbal,
    Actuator::Galvo,
    Actuator::Both,
    Actuator::Stepper,
];

/// A core with `variant`'s settings (those the settings refuse left out)
/// drawing on `actuator`.
fn core(variant: usize, actuator: Actuator) -> Core {
    let mut core = Core::new(Instant::from_millis(0));
    for &(name, value) in VARIANTS[variant] {
        let param = find_param(name).expect("a parameter");
        let _ = core.settings.set(param, value);
    }
    core.geometry_changed();
    core.actuator = actuator;
    core
}

/// The soft-limit check `core` runs with: (fast path, exact check, the
/// check) of a block.
struct Check<'a>(&'a Core);

impl Check<'_> {
    fn inner(&self) -> ReachCheck<'_> {
        ReachCheck::new(&self.0.settings, &self.0.aimer)
    }
    fn surely(&self, b: &Block) -> bool {
        self.inner().surely(b, self.0.drivers(), self.0.reach)
    }
    fn exactly(&self, b: &Block) -> bool {
        self.inner().exactly(b, self.0.drivers())
    }
    fn block(&self, b: &Block) -> bool {
        self.inner().block(b, self.0.drivers(), self.0.reach)
    }
}

fn check(core: &Core) -> Check<'_> {
    Check(core)
}

fn point(x_mm: f64, y_mm: f64) -> PointMm {
    PointMm { x_mm, y_mm }
}

fn block(from: PointMm, to: PointMm, arc: Option<(PointMm, bool)>) -> Block {
    match arc {
        None => Block::Rapid { from, to },
        Some((centre, clockwise)) => Block::Arc {
            arc: Arc::new(from, to, centre, clockwise),
            feed_mm_min: 600.0,
            laser: Laser::default(),
        },
    }
}

/// A block with its points in the board's extent grown by a fifth (the
/// fractions scale with it): a line, or an arc about a centre with its
/// end on the circle.
fn arb_block() -> impl Strategy<Value = ([f64; 4], Option<(f64, f64, bool)>)> {
    let f = -0.6..0.6f64;
    (
        [f.clone(), f.clone(), f.clone(), f],
        prop::option::of((0.0..0.5f64, -3.2..3.2f64, any::<bool>())),
    )
}

fn half_board_mm(core: &Core) -> [f64; 2] {
    let s = &core.settings;
    [
        s.grid_pitch_cm * f64::from(s.grid_cols) * 5.0,
        s.grid_pitch_cm * f64::from(s.grid_rows) * 5.0,
    ]
}

fn make(core: &Core, f: [f64; 4], arc: Option<(f64, f64, bool)>) -> Block {
    let [w, h] = half_board_mm(core);
    let from = point(f[0] * 2.0 * w, f[1] * 2.0 * h);
    match arc {
        None => block(from, point(f[2] * 2.0 * w, f[3] * 2.0 * h), None),
        Some((r, a, clockwise)) => {
            let r = r * w;
            let centre = point(from.x_mm - r * a.cos(), from.y_mm - r * a.sin());
            let b = a + f[2] * 10.0;
            let to = point(centre.x_mm + r * b.cos(), centre.y_mm + r * b.sin());
            block(from, to, Some((centre, clockwise)))
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn the_fast_path_never_passes_what_the_exact_check_refuses(
        variant in 0..VARIANTS.len(),
        actuator in 0..ACTUATORS.len(),
        (f, arc) in arb_block(),
    ) {
        let core = core(variant, ACTUATORS[actuator]);
        let b = make(&core, f, arc);
        if check(&core).surely(&b) {
            prop_assert!(check(&core).exactly(&b), "{b:?}");
        }
        prop_assert_eq!(check(&core).block(&b), check(&core).exactly(&b));
    }
}

#[test]
fn the_fast_path_passes_most_blocks_on_the_board() {
    for variant in 0..COVERED {
        for actuator in ACTUATORS {
            let core = core(variant, actuator);
            let (mut fast, mut exact) = (0, 0);
            let mut rng = 0x2545_f491_4f6c_83f0_u64;
            let mut next = || {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                (rng >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            for _ in 0..400 {
                let f = [next(), next(), next(), next()];
                let arc = (next() > 0.0).then(|| (0.1 + 0.2 * next(), 6.0 * next(), next() > 0.0));
                let b = make(&core, [f[0] * 0.4, f[1] * 0.4, f[2] * 0.4, f[3] * 0.4], arc);
                fast += u32::from(check(&core).surely(&b));
                exact += u32::from(check(&core).exactly(&b));
            }
            std::println!("variant {variant} {actuator:?}: {fast} of {exact}");
            // Blocks within the middle 40 % of the board (arcs may leave
            // it): most are reachable, and most of those pass at once.
            assert!(exact > 200, "variant {variant} {actuator:?}: {exact}");
            assert!(
                fast * 10 >= exact * 7,
                "variant {variant} {actuator:?}: {fast} of {exact}"
            );
        }
    }
}

#[test]
fn a_rolled_board_takes_the_exact_check() {
    let core = core(VARIANTS.len() - 1, Actuator::Gimbal);
    let b = block(PointMm::ZERO, point(1.0, 1.0), None);
    assert!(!check(&core).surely(&b));
    assert!(check(&core).block(&b));
}

#[test]
fn off_the_board_is_never_sure() {
    for actuator in ACTUATORS {
        let core = core(0, actuator);
        let [w, h] = half_board_mm(&core);
        let inside = block(PointMm::ZERO, point(w * 0.5, h * 0.5), None);
        assert!(check(&core).surely(&inside), "{actuator:?}");
        let off = block(PointMm::ZERO, point(w * 1.01, 0.0), None);
        assert!(!check(&core).surely(&off), "{actuator:?}");
        assert!(!check(&core).block(&off), "{actuator:?}");
        // An arc whose circle leaves the board though its ends do not.
        let r = h * 1.2;
        assert!(r < w);
        let bulge = block(point(r, 0.0), point(-r, 0.0), Some((PointMm::ZERO, true)));
        assert!(!check(&core).surely(&bulge), "{actuator:?}");
    }
}
