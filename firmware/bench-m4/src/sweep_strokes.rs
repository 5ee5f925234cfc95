//! The stroke sweep: [`STROKES`] seeded random G-code-like strokes with
//! close corners, marked by the loop half by half (`sweep.stroke.steady`,
//! `.refill`, `.prep`: the dearest of all strokes, each with its input).
//!
//! Kinds, in turn: hairpins (a long line, a 0.3–1.5 mm turn, a long line
//! back), short sharp segments (0.2–2 mm, turns of 90–178°), chords of a
//! small arc (r 0.5–4 mm, turns of 17–69°) and reversals (a line and
//! straight back). Each input starts anywhere in ±70 mm: a stroke of four
//! segments, then [`PIECES`] pieces of two (`StrokeCm::continuing`, as
//! the G-code sender sends the lines ahead), each group of the next kind.

use core::fmt::Write;

use laser_app::domain::{Figure, PointCm, StrokeCm};
use laser_app::galvo::{DacSample, GalvoLoop, GalvoRequest, ScanPhase};

use crate::galvo_loop::{JobCost, m4_loop, measure_job, settle};
use crate::harness::{Bench, HALF, Name};
use crate::sweep::{Rng, SEED, report_median};

/// Mixed into [`SEED`] for this sweep.
const STROKE_SEED: u64 = 0x5eed;
/// Inputs tried (a stroke and its pieces each).
pub const STROKES: u32 = 200;
/// Segments of the stroke (its capacity).
const SEGMENTS: usize = StrokeCm::MAX_SEGMENTS;
/// Segments per joined piece (the G-code sender's `AHEAD_LINES`).
const PIECE_SEGMENTS: usize = SEGMENTS / 2;
/// Pieces joined to each stroke.
const PIECES: usize = 3;
/// Corners of one input: the start and every segment's end.
const CORNERS: usize = SEGMENTS + PIECES * PIECE_SEGMENTS + 1;

/// One input's corners, mm: the start and its segments' ends.
type Corners = [[f64; 2]; CORNERS];

/// Fills `c[1..]` with segments of kind `kind` from `c[0]`, heading
/// `heading` (rad) at first, mm.
fn segments(rng: &mut Rng, kind: u32, c: &mut [[f64; 2]], heading: f64) {
    let Some(&start) = c.first() else { return };
    let mut dir = heading;
    let mut at = start;
    let arc_r = rng.range(0.5, 4.0);
    let arc_turn = rng.sign() * rng.range(0.3, 1.2);
    for (i, corner) in c.iter_mut().enumerate().skip(1) {
        let len = match kind {
            // Hairpin: long, short turn, long back, short.
            0 => {
                if i % 2 == 1 {
                    rng.range(10.0, 40.0)
                } else {
                    rng.range(0.3, 1.5)
                }
            }
            // Short sharp segments.
            1 => rng.range(0.2, 2.0),
            // Chords of a small arc: 2·r·sin(turn/2).
            2 => 2.0 * arc_r * libm::sin(0.5 * arc_turn.abs()),
            // Reversals: a line and straight back.
            _ => rng.range(1.0, 20.0),
        };
        if i > 1 {
            dir += match kind {
                0 => rng.sign() * rng.range(1.45, 1.65),
                1 => rng.sign() * rng.range(1.571, 3.107),
                2 => arc_turn,
                _ => core::f64::consts::PI,
            };
        }
        at = [at[0] + len * libm::cos(dir), at[1] + len * libm::sin(dir)];
        *corner = at;
    }
}

/// The stroke of `corners` (mm), or a piece continuing the stroke being
/// marked.
fn stroke(corners: &[[f64; 2]], continuing: bool) -> Option<StrokeCm> {
    let cm = |p: [f64; 2]| PointCm::new(p[0] * 0.1, p[1] * 0.1);
    let (first, rest) = corners.split_first()?;
    let mut s = if continuing {
        StrokeCm::continuing(cm(*first))?
    } else {
        StrokeCm::new(cm(*first))?
    };
    for p in rest {
        s.line_to(cm(*p)).then_some(())?;
    }
    Some(s)
}

/// A stroke and its joined pieces: their corners, mm.
#[derive(Debug, Clone, Copy)]
struct StrokeInput {
    index: u32,
    corners: Corners,
}

impl StrokeInput {
    /// The stroke's corners, then each piece's (sharing its first corner
    /// with the end of the group before).
    fn groups(&self) -> impl Iterator<Item = &[[f64; 2]]> {
        let c = &self.corners;
        let stroke = c.get(..=SEGMENTS).into_iter();
        let pieces = (0..PIECES).filter_map(move |k| {
            let first = SEGMENTS + k * PIECE_SEGMENTS;
            c.get(first..=first + PIECE_SEGMENTS)
        });
        stroke.chain(pieces)
    }
}

/// The `i`th input of the sweep.
fn stroke_input(rng: &mut Rng, i: u32) -> StrokeInput {
    let mut corners = [[rng.range(-70.0, 70.0), rng.range(-70.0, 70.0)]; CORNERS];
    let mut heading = rng.range(0.0, core::f64::consts::TAU);
    let mut first = 0;
    for (group, len) in (0u32..).zip([SEGMENTS].into_iter().chain([PIECE_SEGMENTS; PIECES])) {
        if let Some(c) = corners.get_mut(first..=first + len) {
            segments(rng, (i + group) % 4, c, heading);
            let [a, b] = [c[len - 1], c[len]];
            heading = libm::atan2(b[1] - a[1], b[0] - a[0]) + rng.sign() * rng.range(1.2, 3.0);
        }
        first += len;
    }
    StrokeInput { index: i, corners }
}

/// Writes a stroke input's corners, mm.
fn describe(out: &mut impl Write, s: &StrokeInput) {
    let _ = write!(
        out,
        "input {} of seed {:#x}, corners (mm, a stroke of {SEGMENTS} then pieces of {PIECE_SEGMENTS}):",
        s.index,
        SEED ^ STROKE_SEED
    );
    for p in &s.corners {
        let _ = write!(out, " ({:.3},{:.3})", p[0], p[1]);
    }
}

/// Marks one input from a loop resting at its start; `None` when a
/// stroke was refused (it leaves the field).
fn mark(galvo: &mut GalvoLoop, half: &mut [DacSample; HALF], s: &StrokeInput) -> Option<JobCost> {
    let [x_mm, y_mm] = s.corners[0];
    galvo.request(GalvoRequest::Point {
        seq: 1,
        x_mm: x_mm as f32,
        y_mm: y_mm as f32,
        dwell_us: 0,
    });
    settle(galvo, half);
    for (seq, corners) in (2..).zip(s.groups()) {
        let request = GalvoRequest::Path {
            seq,
            path: Figure::Stroke(stroke(corners, seq > 2)?),
            mark_speed_mm_s: None,
        };
        if galvo.request(request).is_some() {
            return None;
        }
    }
    Some(measure_job(galvo, half, ScanPhase::Marking))
}

/// The stroke sweep (see the module documentation).
pub fn stroke_sweep(b: &mut Bench) {
    let id = "sweep.stroke";
    let mut galvo = match m4_loop(Default::default()) {
        Ok(g) => g,
        Err(e) => return b.fail(id, e),
    };
    let mut half = [DacSample::default(); HALF];
    let mut rng = Rng::new(SEED ^ STROKE_SEED);
    // The dearest of each figure: (ticks, units, input).
    let mut worst: [Option<(u32, u32, StrokeInput)>; 3] = [None; 3];
    // Every input's figures (ticks, units), for the medians.
    let mut all = [[(0u32, 1u32); STROKES as usize]; 3];
    let mut counted = [0usize; 3];
    let (mut tried, mut waited) = (0u32, 0u32);
    for i in 0..4 * STROKES {
        if tried == STROKES {
            break;
        }
        let input = stroke_input(&mut rng, i);
        let Some(cost) = mark(&mut galvo, &mut half, &input) else {
            // Refused (off the field): the next input from a settled loop.
            settle(&mut galvo, &mut half);
            continue;
        };
        waited += u32::from(cost.waited);
        tried += 1;
        let figures = [
            cost.steady.map(|t| (t, HALF as u32)),
            Some((cost.refill, 1)),
            cost.prep,
        ];
        for (((slot, figure), list), count) in worst
            .iter_mut()
            .zip(figures)
            .zip(all.iter_mut())
            .zip(counted.iter_mut())
        {
            let Some((t, n)) = figure else { continue };
            if let Some(entry) = list.get_mut(*count) {
                *entry = (t, n);
                *count += 1;
            }
            if slot.is_none_or(|(wt, wn, _)| {
                u64::from(t) * u64::from(wn) > u64::from(wt) * u64::from(n)
            }) {
                *slot = Some((t, n, input));
            }
        }
    }
    if tried < STROKES {
        b.fail(id, ("strokes refused; measured", tried));
    }
    // A piece that could not be joined in time is prepared on its own
    // once the stroke ends: the refill holds the spot dark until then
    // (cheaper halves, so the worst case stands; reported for the record).
    let _ = writeln!(
        b.out,
        "note {id}: {waited} of {tried} inputs waited for an unprepared piece"
    );
    let mut name = Name::new();
    let medians = all.iter_mut().zip(counted);
    for ((suffix, slot), (list, count)) in [".steady", ".refill", ".prep"]
        .into_iter()
        .zip(worst)
        .zip(medians)
    {
        name.set(id, suffix);
        let Some((ticks, units, input)) = slot else {
            b.fail(name.as_str(), "no stroke measured");
            continue;
        };
        b.report(name.as_str(), ticks, units);
        report_median(b, name.as_str(), list.get_mut(..count).unwrap_or_default());
        let _ = write!(b.out, "worst {} {tried} ", name.as_str());
        describe(&mut b.out, &input);
        let _ = writeln!(b.out);
        b.out.flush();
    }
}
