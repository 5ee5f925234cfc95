//! The galvo loop's half-buffer fills: holding, marking a line, a circle
//! (r = 40 mm) and a G-code stroke, joining a continuation to a stroke
//! being marked, jumping; `GalvoLoop::new`.

use core::hint::black_box;

use laser_app::domain::{Figure, PointCm, Rotation, StrokeCm};
use laser_app::galvo::{
    DacSample, DacStream, GalvoConfig, GalvoError, GalvoLoop, GalvoRequest, Half, ScanPhase,
    Underrun,
};

use crate::harness::{Bench, HALF, Name, window};

/// The board the loop is built for here, as the firmware builds it
/// (`GalvoLoop::for_dac`): an M4F, jumps planned time-optimal in `f32`
/// only (the default `DacStream::F64_PLANNING`). The bench drives the
/// loop's `fill` itself; this DAC only names the board.
struct M4Dac;

impl DacStream for M4Dac {
    fn half_len(&self) -> usize {
        HALF
    }
    fn set_sample_period(&mut self, _period_s: f64) {}
    fn holds(&self, _sample: DacSample) -> bool {
        false
    }
    async fn write_half(&mut self, _half: Half<'_>) -> Result<(), Underrun> {
        Ok(())
    }
    async fn repeat_half(&mut self) {}
}

/// The loop as the firmware builds it.
pub fn m4_loop(config: GalvoConfig) -> Result<GalvoLoop, GalvoError> {
    GalvoLoop::for_dac::<M4Dac>(config)
}

/// Runs the loop until it is idle (not measured).
pub fn settle(galvo: &mut GalvoLoop, half: &mut [DacSample; HALF]) {
    for _ in 0..10_000 {
        if galvo.phase() == ScanPhase::Idle && galvo.queued_points() == 0 {
            return;
        }
        galvo.fill(half, |_| {});
    }
}

/// What one job cost, half by half (timer ticks; see [`measure_job`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct JobCost {
    /// The dearest refill that started and ended in the steady phase.
    pub steady: Option<u32>,
    /// The dearest refill of the job.
    pub refill: u32,
    /// The dearest prep call that prepared a step: (ticks, steps).
    pub prep: Option<(u32, u32)>,
    /// A refill waited for a step the prep stage had not prepared.
    pub waited: bool,
}

/// Runs the job queued in `galvo` to its end as `GalvoLoop::run` runs it
/// (the prep stage between halves, then the refill) and measures every
/// half: see [`JobCost`]; `steady` is the phase whose halves count as
/// steady.
pub fn measure_job(
    galvo: &mut GalvoLoop,
    half: &mut [DacSample; HALF],
    steady: ScanPhase,
) -> JobCost {
    let mut cost = JobCost::default();
    let unprepared = galvo.unprepared_samples();
    for _ in 0..20_000usize {
        let before = galvo.phase();
        if before == ScanPhase::Idle && galvo.queued_points() == 0 {
            break;
        }
        let mut steps = 0;
        let ticks = window(|| steps = galvo.prep());
        if steps > 0 && cost.prep.is_none_or(|(t, n)| ticks / steps as u32 > t / n) {
            cost.prep = Some((ticks, steps as u32));
        }
        let ticks = window(|| galvo.refill(half, |_| {}));
        cost.refill = cost.refill.max(ticks);
        if before == steady && galvo.phase() == steady {
            cost.steady = Some(cost.steady.map_or(ticks, |t| t.max(ticks)));
        }
    }
    cost.waited = galvo.unprepared_samples() != unprepared;
    cost
}

/// Measures every half of a job as `GalvoLoop::run` runs it: the prep
/// stage between halves, then the refill. `<id>.steady` is the dearest
/// refill that starts and ends in `steady` (the per-sample figure),
/// `<id>.refill` the dearest refill of the job, `<id>.prep` the dearest
/// prep call that prepared a step (per step).
fn job_halves(
    b: &mut Bench,
    id: &str,
    galvo: &mut GalvoLoop,
    half: &mut [DacSample; HALF],
    steady: ScanPhase,
) {
    let cost = measure_job(galvo, half, steady);
    let mut name: Name = Name::new();
    if cost.waited {
        return b.fail(id, "the refill waited for an unprepared step");
    }
    match cost.steady {
        Some(ticks) => {
            name.set(id, ".steady");
            b.report(name.as_str(), ticks, HALF as u32);
        }
        None => b.fail(id, "no steady half"),
    }
    name.set(id, ".refill");
    b.report(name.as_str(), cost.refill, 1);
    name.set(id, ".prep");
    match cost.prep {
        Some((ticks, steps)) => b.report(name.as_str(), ticks, steps),
        None => b.fail(id, "nothing prepared"),
    }
}

/// `DacStream::holds` as the simulated DAC answers it (firmware/sim's
/// `dac.rs`; the target's DAC driver is not written yet): both halves hold
/// nothing but `sample`.
#[inline(never)]
fn dac_holds(buffers: &[[DacSample; HALF]; 2], sample: DacSample) -> bool {
    buffers.iter().all(|h| h.iter().all(|s| *s == sample))
}

/// The galvo loop's half-buffer fills: holding, marking a line, marking a
/// circle (r = 40 mm), jumping; `GalvoLoop::new`.
pub fn loop_halves(b: &mut Bench) {
    let config = GalvoConfig::default();
    let ticks = window(|| m4_loop(config));
    b.report("loop.new", ticks, 1);
    let mut galvo = match m4_loop(config) {
        Ok(g) => g,
        Err(e) => return b.fail("loop.new", e),
    };
    let mut half = [DacSample::default(); HALF];
    holding(b, &mut galvo, &mut half);
    reconfigure(b, &mut galvo, config, &mut half);
    marking(b, &mut galvo, &mut half);
    joining(b, &mut galvo, &mut half);
    jumping(b, config, &mut half);
}

/// Holding: the first halves after the loop goes idle, then the halves
/// the DAC already holds; the hold sample alone.
#[inline(always)]
fn holding(b: &mut Bench, galvo: &mut GalvoLoop, half: &mut [DacSample; HALF]) {
    // Holding, as `GalvoLoop::run` does it. The first two halves after the
    // loop goes idle are filled: one hold sample computed and copied into
    // the half (`loop.holding.refill`, the dearest holding half). From then
    // on both DAC halves hold it and every wake-up only computes the hold
    // sample and asks the DAC whether both halves hold it, then writes
    // nothing (`loop.holding.steady`, per sample of the half).
    let mut worst = 0u32;
    for _ in 0..16 {
        let mut computed = 0;
        worst = worst.max(window(|| computed = galvo.fill(half, |_| {})));
        if computed != 1 {
            return b.fail("loop.holding.refill", ("computed", computed));
        }
    }
    b.report("loop.holding.refill", worst, 1);
    // The DAC's double buffer after those two halves.
    let buffers = [*half, *half];
    let mut worst = 0u32;
    for _ in 0..16 {
        let mut repeated = false;
        worst = worst.max(window(|| {
            repeated = galvo
                .hold_sample()
                .is_some_and(|hold| dac_holds(black_box(&buffers), hold));
        }));
        if !repeated {
            return b.fail(
                "loop.holding.steady",
                "the DAC does not hold the hold sample",
            );
        }
    }
    b.report("loop.holding.steady", worst, HALF as u32);
    let ticks = window(|| {
        for _ in 0..64 {
            black_box(galvo.hold_sample());
        }
    });
    b.report("loop.hold_sample", ticks, 64);
}

/// New parameters, mirror model kept (a new marking speed), applied at a
/// half boundary with the loop idle: the rebuild and one held sample.
#[inline(always)]
fn reconfigure(
    b: &mut Bench,
    galvo: &mut GalvoLoop,
    config: GalvoConfig,
    half: &mut [DacSample; HALF],
) {
    let faster = GalvoConfig {
        mark_speed_mm_s: config.mark_speed_mm_s * 1.5,
        ..config
    };
    let ticks = window(|| {
        galvo.configure(faster);
        galvo.fill(&mut half[..1], |_| {});
    });
    b.report("loop.reconfigure", ticks, 1);
    // Back to the benchmarked parameters (not measured).
    galvo.configure(config);
    galvo.fill(&mut half[..1], |_| {});
}

/// A G-code stroke at its dearest: four lines (open, so its end needs
/// its own IK), a zigzag from (-60, -20) mm to (60, 20) mm.
fn g_code_stroke() -> Option<StrokeCm> {
    let mut stroke = StrokeCm::new(PointCm::new(-6.0, -2.0))?;
    for (x_cm, y_cm) in [(-3.0, 2.0), (0.0, -2.0), (3.0, 2.0), (6.0, 2.0)] {
        stroke.line_to(PointCm::new(x_cm, y_cm)).then_some(())?;
    }
    Some(stroke)
}

/// Marking a line, a circle (r = 40 mm), a G-code stroke of four lines and
/// the tuning figure, half by half.
#[inline(always)]
fn marking(b: &mut Bench, galvo: &mut GalvoLoop, half: &mut [DacSample; HALF]) {
    let Some(stroke) = g_code_stroke() else {
        return b.fail("loop.stroke", "the stroke was refused");
    };
    // Marking: first go to the stroke start (not measured), so the job's
    // own jump is zero-length and its halves hold marking only.
    let jobs = [
        (
            "loop.line",
            [-80.0f32, 10.0],
            // (-80, 10) mm to (80, -10) mm.
            Figure::Line {
                from: PointCm::new(-8.0, 1.0),
                to: PointCm::new(8.0, -1.0),
            },
        ),
        (
            "loop.arc_r40",
            [0.0f32, 40.0],
            // Radius 40 mm.
            Figure::Circle {
                centre: PointCm::new(0.0, 0.0),
                radius_cm: 4.0,
                rotation: Rotation::Ccw,
            },
        ),
        (
            "loop.stroke",
            [-60.0f32, -20.0],
            // A G-code stroke of four lines.
            Figure::Stroke(stroke),
        ),
        (
            "loop.tuning",
            [-40.0f32, 40.0],
            // The tuning figure, 80 mm: a square, a circle and a cross,
            // with jumps between the strokes (its steps: a jump and a
            // stroke each).
            Figure::Tuning {
                centre: PointCm::new(0.0, 0.0),
                size_cm: 8.0,
            },
        ),
    ];
    for (seq, (id, [x_mm, y_mm], path)) in (1u32..).zip(jobs) {
        galvo.request(GalvoRequest::Point {
            seq: 100 + seq,
            x_mm,
            y_mm,
            dwell_us: 0,
        });
        settle(galvo, half);
        if let Some(refused) = galvo.request(GalvoRequest::Path {
            seq,
            path,
            mark_speed_mm_s: None,
        }) {
            b.fail(id, refused);
            continue;
        }
        job_halves(b, id, galvo, half, ScanPhase::Marking);
    }
}

/// Joining: the prep step that joins a G-code piece of two lines
/// continuing the four-line stroke being marked (`loop.join.prep`: its
/// lines into the running path planner, the look-ahead passes, its end
/// IK).
#[inline(always)]
fn joining(b: &mut Bench, galvo: &mut GalvoLoop, half: &mut [DacSample; HALF]) {
    let piece = StrokeCm::continuing(PointCm::new(6.0, 2.0)).and_then(|mut s| {
        for (x_cm, y_cm) in [(7.0, -2.0), (8.0, 2.0)] {
            s.line_to(PointCm::new(x_cm, y_cm)).then_some(())?;
        }
        Some(s)
    });
    let (Some(stroke), Some(piece)) = (g_code_stroke(), piece) else {
        return b.fail("loop.join.prep", "the strokes were refused");
    };
    galvo.request(GalvoRequest::Point {
        seq: 300,
        x_mm: -60.0,
        y_mm: -20.0,
        dwell_us: 0,
    });
    settle(galvo, half);
    for (seq, path) in [(301, Figure::Stroke(stroke)), (302, Figure::Stroke(piece))] {
        let request = GalvoRequest::Path {
            seq,
            path,
            mark_speed_mm_s: None,
        };
        if let Some(refused) = galvo.request(request) {
            return b.fail("loop.join.prep", refused);
        }
    }
    let mut joined: Option<u32> = None;
    let mut dones = 0u32;
    for _ in 0..20_000usize {
        if galvo.phase() == ScanPhase::Idle && galvo.queued_points() == 0 {
            break;
        }
        let (waiting, mut steps) = (galvo.queued_points(), 0);
        let ticks = window(|| steps = galvo.prep_up_to(1));
        if waiting == 1 && galvo.queued_points() == 0 && steps == 1 {
            joined = Some(joined.map_or(ticks, |t| t.max(ticks)));
        }
        galvo.refill(half, |e| {
            dones += u32::from(matches!(e, laser_app::galvo::GalvoEvent::Done { .. }))
        });
    }
    match joined {
        Some(ticks) if dones == 2 => b.report("loop.join.prep", ticks, 1),
        _ => b.fail(
            "loop.join.prep",
            ("joined, done", (joined.is_some(), dones)),
        ),
    }
}

/// Jumping: the prep that plans the jump, the refill that starts it, and
/// the jump's samples after that.
#[inline(always)]
fn jumping(b: &mut Bench, config: GalvoConfig, half: &mut [DacSample; HALF]) {
    // Jumping (−80, −80) → (80, 80) mm, as `GalvoLoop::run` does it: the
    // prep stage plans the jump (`loop.jump.prep`) before the refill that
    // starts it (`loop.jump.refill`); `loop.jump.steady` covers the jump's
    // samples after that refill's first, counted on one run and measured
    // on an identical one (the loop is deterministic).
    let jumping = |half: &mut [DacSample; HALF]| {
        let mut galvo = m4_loop(config)?;
        for (seq, [x_mm, y_mm]) in [(200, [-80.0, -80.0]), (201, [80.0, 80.0])] {
            if let Some(laser_app::galvo::GalvoEvent::Refused { error, .. }) =
                galvo.request(GalvoRequest::Point {
                    seq,
                    x_mm,
                    y_mm,
                    dwell_us: 0,
                })
            {
                return Err(error);
            }
            if seq == 200 {
                settle(&mut galvo, half);
            }
        }
        Ok(galvo)
    };
    let runs = (jumping(half), jumping(half), jumping(half));
    let (Ok(mut first), Ok(mut counted), Ok(mut measured)) = runs else {
        return b.fail("loop.jump", "setup");
    };
    let mut steps = 0;
    let ticks = window(|| steps = first.prep());
    if steps != 1 {
        return b.fail("loop.jump.prep", ("steps", steps));
    }
    b.report("loop.jump.prep", ticks, 1);
    let ticks = window(|| first.refill(half, |_| {}));
    if first.unprepared_samples() != 0 {
        return b.fail("loop.jump.refill", "unprepared");
    }
    b.report("loop.jump.refill", ticks, 1);
    counted.prep();
    measured.prep();
    counted.refill(&mut half[..1], |_| {});
    let mut n = 0usize;
    while counted.phase() == ScanPhase::Jumping && n < HALF {
        counted.refill(&mut half[..1], |_| {});
        n += 1;
    }
    measured.refill(&mut half[..1], |_| {});
    let n = n.max(1);
    let ticks = window(|| measured.refill(&mut half[..n], |_| {}));
    b.report("loop.jump.steady", ticks, n as u32);
}
