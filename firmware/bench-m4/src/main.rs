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
use galvo_planner::model::RIGID_STATES;
use galvo_planner::{
    Discrete, JumpSync, MarkLimits, Method, PathPlanner, RigidParams, XyIntegrator, plan_jump,
    plan_xy_jump,
};
use kinematics_core::{BoardPoint, DacAxis, ErrorModel, Galvo, Gimbal, MirrorAngles, PointMm};
use laser_app::domain::{Figure, PointCm, Rotation};
use laser_app::galvo::{DacSample, GalvoConfig, GalvoLoop, GalvoRequest, ScanPhase};

mod semihosting;
mod timer;

use semihosting::Out;

/// Samples per DMA half buffer (1.28 ms at 100 kHz).
const HALF: usize = 128;
/// Jump input samples the integrator holds (the loop's `INTEGRATOR_CAPACITY`).
const CAPACITY: usize = 1024;
/// Iterations of the calibration loop (2 instructions each).
const CALIBRATION_ITERATIONS: u32 = 1_000_000;

/// Ticks of one window around `f`, with the window's own cost (two timer
/// reads) not removed: xtask subtracts the `empty` window.
#[inline(never)]
fn window<R>(f: impl FnOnce() -> R) -> u32 {
    let t0 = timer::now();
    let r = f();
    let t1 = timer::now();
    black_box(r);
    t0.wrapping_sub(t1)
}

/// `2·n` instructions of `subs`/`bne`, plus the window's fixed cost.
#[inline(never)]
fn calibration_loop(n: u32) {
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

struct Bench {
    out: Out,
    failures: u32,
}

impl Bench {
    fn report(&mut self, id: &str, ticks: u32, units: u32) {
        let _ = writeln!(self.out, "bench {id} {ticks} {units}");
        self.out.flush();
    }

    fn fail(&mut self, id: &str, what: impl core::fmt::Debug) {
        self.failures += 1;
        let _ = writeln!(self.out, "error {id} {what:?}");
        self.out.flush();
    }

    /// `units` repetitions of `f` in one window.
    fn repeat<R>(&mut self, id: &str, units: u32, mut f: impl FnMut() -> R) {
        let ticks = window(|| {
            for _ in 0..units {
                black_box(f());
            }
        });
        self.report(id, ticks, units);
    }
}

fn deg(d: f64) -> f64 {
    d * core::f64::consts::PI / 180.0
}

#[entry]
fn main() -> ! {
    timer::start();
    let mut b = Bench {
        out: Out::new(),
        failures: 0,
    };
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

    self_checks(&mut b);
    kinematics(&mut b);
    integrator_and_path(&mut b);
    loop_halves(&mut b);
    planning(&mut b);

    let _ = writeln!(b.out, "done {}", b.failures);
    b.out.flush();
    semihosting::exit(b.failures == 0)
}

/// What only the target can check: the FPU square root (`VSQRT.F32` in
/// `asm!`, the host runs the libm fallback) against `libm::sqrtf` bit for
/// bit, and the f32 DAC conversion against the f64 one on the target's
/// code path.
fn self_checks(b: &mut Bench) {
    let mut checked = 0u32;
    let mut x = 1.0e-38f32;
    while x < 3.0e38 {
        for k in 0..16u8 {
            let v = x * (1.0 + f32::from(k) * 0.0625);
            let (hw, sw) = (kinematics_core::sqrt_f32(v), libm::sqrtf(v));
            if hw.to_bits() != sw.to_bits() {
                return b.fail("check.sqrt", (v, hw, sw));
            }
            checked += 1;
        }
        x *= 1.5;
    }
    for v in [0.0f32, -0.0, f32::INFINITY, f32::MIN_POSITIVE, 1.0e-45] {
        if kinematics_core::sqrt_f32(v).to_bits() != libm::sqrtf(v).to_bits() {
            return b.fail("check.sqrt", v);
        }
    }
    if !kinematics_core::sqrt_f32(-1.0).is_nan() {
        return b.fail("check.sqrt", -1.0f32);
    }
    let (d32, d64) = (DacAxis::<f32>::default(), DacAxis::<f64>::default());
    for i in 0..=20_000u32 {
        let theta = (i as f32 / 10_000.0 - 1.0) * 0.25;
        let (c32, c64) = (
            d32.angle_to_code(theta),
            d64.angle_to_code(f64::from(theta)),
        );
        let close = match (c32, c64) {
            (Ok(a), Ok(b)) => a.clamped == b.clamped && a.code.abs_diff(b.code) <= 1,
            _ => false,
        };
        if !close {
            return b.fail("check.dac", theta);
        }
    }
    let _ = writeln!(b.out, "check sqrt+dac ok {checked}");
    b.out.flush();
}

/// Galvo IK and DAC mapping per sample, gimbal IK and compensation per
/// point.
fn kinematics(b: &mut Bench) {
    let g32 = Galvo::<f32>::default();
    let g64 = Galvo::<f64>::default();
    const N: u32 = 1000;
    // Points spread over the field, varied per call so nothing is hoisted.
    let p32 = |i: u32| {
        let t = (i % 97) as f32;
        PointMm::new(-150.0 + 3.1 * t, 120.0 - 2.4 * t)
    };
    b.repeat("galvo.ik.f32", N, {
        let mut i = 0;
        move || {
            i += 1;
            g32.geometry.ik(black_box(p32(i)))
        }
    });
    b.repeat("galvo.board_to_codes.f32", N, {
        let mut i = 0;
        move || {
            i += 1;
            g32.board_to_codes(black_box(p32(i)))
        }
    });
    let map = match kinematics_core::SampleMap::new(&g32) {
        Ok(m) => m,
        Err(e) => return b.fail("galvo.sample_map", e),
    };
    b.repeat("galvo.sample_map.board_to_codes", N, {
        let mut i = 0;
        move || {
            i += 1;
            let p = black_box(p32(i));
            map.board_to_codes(p.x_mm, p.y_mm)
        }
    });
    b.repeat("galvo.sample_map.angles_to_codes", N, {
        let mut i = 0u32;
        move || {
            i += 1;
            let t = (i % 89) as f32 * 0.004 - 0.18;
            map.angles_to_codes(black_box(t), black_box(-t))
        }
    });
    b.repeat("galvo.angles_to_codes.f32", N, {
        let mut i = 0u32;
        move || {
            i += 1;
            let t = (i % 89) as f32 * 0.004 - 0.18;
            g32.angles_to_codes(black_box(MirrorAngles {
                x_rad: t,
                y_rad: -t,
            }))
        }
    });
    b.repeat("galvo.board_to_codes.f64", N, {
        let mut i = 0;
        move || {
            i += 1;
            let p = p32(i);
            g64.board_to_codes(black_box(PointMm::new(
                f64::from(p.x_mm),
                f64::from(p.y_mm),
            )))
        }
    });
    let dac = DacAxis::<f32>::default();
    b.repeat("dac.angle_to_code.f32", N, {
        let mut i = 0u32;
        move || {
            i += 1;
            dac.angle_to_code(black_box((i % 89) as f32 * 0.004 - 0.18))
        }
    });

    let gimbal = Gimbal::default();
    b.repeat("gimbal.ik_wire", 100, {
        let mut i = 0u32;
        move || {
            i += 1;
            let t = f64::from(i % 13);
            gimbal.ik_wire(black_box(BoardPoint::new(-10.0 + 1.5 * t, 6.0 - t)))
        }
    });
    let model = ErrorModel::new(
        [0.12, 0.004, -0.002, 1e-4, -2e-5, 5e-5],
        [-0.08, -0.003, 0.005, -6e-5, 3e-5, 1e-4],
    );
    b.repeat("error_model.compensate", 100, {
        let mut i = 0u32;
        move || {
            i += 1;
            let t = f64::from(i % 13);
            model.compensate(black_box(PointMm::new(-100.0 + 15.0 * t, 60.0 - 10.0 * t)))
        }
    });
}

/// The reference rigid galvo model discretized at the 10 µs sample
/// period.
fn reference_plant_at_10us() -> Result<Discrete<RIGID_STATES>, galvo_planner::Error> {
    RigidParams::REFERENCE
        .model()
        .and_then(|m| m.discretize(10e-6))
}

/// The per-sample integrator during a jump, the path sampler on lines and
/// arcs, and adding a segment to the look-ahead planner.
fn integrator_and_path(b: &mut Bench) {
    let disc = match reference_plant_at_10us() {
        Ok(d) => d,
        Err(e) => return b.fail("integrator.setup", e),
    };
    let mut mirrors: XyIntegrator<3, CAPACITY> = match XyIntegrator::new(&disc, &disc, [0.0, 0.0]) {
        Ok(m) => m,
        Err(e) => return b.fail("integrator.setup", e),
    };
    // Four queued jumps back and forth, both axes moving; the window
    // covers the samples while both run.
    let (a, z) = ([0.0, 0.0], [deg(10.0), deg(-8.0)]);
    for (from, to) in [(a, z), (z, a), (a, z), (z, a)] {
        let queued = plan_xy_jump(
            &disc,
            &disc,
            from,
            to,
            Method::TimeOptimal,
            JumpSync::Independent,
            CAPACITY,
        )
        .and_then(|jump| mirrors.queue_jump(&jump));
        if let Err(e) = queued {
            return b.fail("integrator.setup", e);
        }
    }
    let steps = mirrors
        .x
        .remaining_samples()
        .min(mirrors.y.remaining_samples()) as u32;
    b.repeat("integrator.xy.step", steps, || mirrors.step());

    let limits = MarkLimits {
        speed_mm_s: 1000.0,
        accel_mm_s2: 1.0e5,
        junction_deviation_mm: 0.01,
        ts_s: 10e-6,
    };
    let line = PathPlanner::<16>::new(limits, [-80.0, 10.0]).and_then(|mut p| {
        p.line_to([80.0, -10.0])?;
        Ok(p)
    });
    let arc = PathPlanner::<16>::new(limits, [0.0, 40.0]).and_then(|mut p| {
        p.arc_to([0.0, 40.0], [0.0, 0.0], true)?;
        Ok(p)
    });
    for (id, planner) in [("path.sample.line", line), ("path.sample.arc", arc)] {
        let mut planner = match planner {
            Ok(p) => p,
            Err(e) => return b.fail(id, e),
        };
        // Into the cruise phase, then a window of samples.
        for _ in 0..2000 {
            planner.next_sample();
        }
        b.repeat(id, 1000, || planner.next_sample());
    }

    // One segment added behind eight buffered ones (junction speed and the
    // backward/forward passes over the buffer).
    let polyline: [[f64; 2]; 8] = core::array::from_fn(|i| {
        let x = -80.0 + 20.0 * i as f64;
        [x, if i % 2 == 0 { 10.0 } else { -10.0 }]
    });
    for (id, arc) in [("path.add.line", false), ("path.add.arc", true)] {
        let (mut ticks, mut units) = (0u32, 0u32);
        for _ in 0..32 {
            let mut p = match PathPlanner::<16>::new(limits, [-100.0, 0.0]) {
                Ok(p) => p,
                Err(e) => return b.fail(id, e),
            };
            if let Err(e) = p.extend_polyline(&polyline, false) {
                return b.fail(id, e);
            }
            let p = &mut p;
            // The pen is at (60, −10) mm.
            let mut added = Ok(());
            ticks += window(|| {
                added = if arc {
                    p.arc_to(black_box([90.0, -10.0]), black_box([75.0, -10.0]), true)
                } else {
                    p.line_to(black_box([90.0, 0.0]))
                };
            });
            if let Err(e) = added {
                return b.fail(id, e);
            }
            units += 1;
        }
        b.report(id, ticks, units);
    }
}

/// Runs the loop until it is idle (not measured).
fn settle(galvo: &mut GalvoLoop, half: &mut [DacSample; HALF]) {
    for _ in 0..10_000 {
        if galvo.phase() == ScanPhase::Idle && galvo.queued_points() == 0 {
            return;
        }
        galvo.fill(half, |_| {});
    }
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
    let (mut steady_max, mut refill_max, mut steady_seen) = (0u32, 0u32, false);
    let mut prep_max: Option<(u32, u32)> = None;
    let unprepared = galvo.unprepared_samples();
    for _ in 0..20_000usize {
        let before = galvo.phase();
        if before == ScanPhase::Idle && galvo.queued_points() == 0 {
            break;
        }
        let mut steps = 0;
        let ticks = window(|| steps = galvo.prep());
        if steps > 0 && prep_max.is_none_or(|(t, n)| ticks / steps as u32 > t / n) {
            prep_max = Some((ticks, steps as u32));
        }
        let ticks = window(|| galvo.refill(half, |_| {}));
        refill_max = refill_max.max(ticks);
        if before == steady && galvo.phase() == steady {
            steady_max = steady_max.max(ticks);
            steady_seen = true;
        }
    }
    let mut name: heapless_name::Name = heapless_name::Name::new();
    if galvo.unprepared_samples() != unprepared {
        return b.fail(id, "the refill waited for an unprepared step");
    }
    if steady_seen {
        name.set(id, ".steady");
        b.report(name.as_str(), steady_max, HALF as u32);
    } else {
        b.fail(id, "no steady half");
    }
    name.set(id, ".refill");
    b.report(name.as_str(), refill_max, 1);
    name.set(id, ".prep");
    match prep_max {
        Some((ticks, steps)) => b.report(name.as_str(), ticks, steps),
        None => b.fail(id, "nothing prepared"),
    }
}

mod heapless_name {
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
fn loop_halves(b: &mut Bench) {
    let config = GalvoConfig::default();
    let ticks = window(|| GalvoLoop::new(config));
    b.report("loop.new", ticks, 1);
    let mut galvo = match GalvoLoop::new(config) {
        Ok(g) => g,
        Err(e) => return b.fail("loop.new", e),
    };
    let mut half = [DacSample::default(); HALF];

    // Holding, as `GalvoLoop::run` does it. The first two halves after the
    // loop goes idle are filled: one hold sample computed and copied into
    // the half (`loop.holding.refill`, the dearest holding half). From then
    // on both DAC halves hold it and every wake-up only computes the hold
    // sample and asks the DAC whether both halves hold it, then writes
    // nothing (`loop.holding.steady`, per sample of the half).
    let mut worst = 0u32;
    for _ in 0..16 {
        let mut computed = 0;
        worst = worst.max(window(|| computed = galvo.fill(&mut half, |_| {})));
        if computed != 1 {
            return b.fail("loop.holding.refill", ("computed", computed));
        }
    }
    b.report("loop.holding.refill", worst, 1);
    // The DAC's double buffer after those two halves.
    let buffers = [half, half];
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
    ];
    for (seq, (id, [x_mm, y_mm], path)) in (1u32..).zip(jobs) {
        galvo.request(GalvoRequest::Point {
            seq: 100 + seq,
            x_mm,
            y_mm,
            dwell_us: 0,
        });
        settle(&mut galvo, &mut half);
        if let Some(refused) = galvo.request(GalvoRequest::Path { seq, path }) {
            b.fail(id, refused);
            continue;
        }
        job_halves(b, id, &mut galvo, &mut half, ScanPhase::Marking);
    }

    // Jumping (−80, −80) → (80, 80) mm, as `GalvoLoop::run` does it: the
    // prep stage plans the jump (`loop.jump.prep`) before the refill that
    // starts it (`loop.jump.refill`); `loop.jump.steady` covers the jump's
    // samples after that refill's first, counted on one run and measured
    // on an identical one (the loop is deterministic).
    let jumping = |half: &mut [DacSample; HALF]| {
        let mut galvo = GalvoLoop::new(config)?;
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
    let runs = (jumping(&mut half), jumping(&mut half), jumping(&mut half));
    let (Ok(mut first), Ok(mut counted), Ok(mut measured)) = runs else {
        return b.fail("loop.jump", "setup");
    };
    let mut steps = 0;
    let ticks = window(|| steps = first.prep());
    if steps != 1 {
        return b.fail("loop.jump.prep", ("steps", steps));
    }
    b.report("loop.jump.prep", ticks, 1);
    let ticks = window(|| first.refill(&mut half, |_| {}));
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

/// Jump planning per method over 0.1°–20° (one axis, mechanical), and
/// two-axis jumps as the loop plans them.
fn planning(b: &mut Bench) {
    let disc = match reference_plant_at_10us() {
        Ok(d) => d,
        Err(e) => return b.fail("plan.setup", e),
    };
    let mut name = heapless_name::Name::new();
    for (method_id, method) in [
        ("plan.optimal", Method::TimeOptimal),
        ("plan.seed", Method::BISECTION),
        ("plan.tcurve", Method::TCurve),
        ("plan.scurve", Method::SCurve),
    ] {
        for (amp_id, amp_deg) in [
            (".0.1deg", 0.1),
            (".1deg", 1.0),
            (".5deg", 5.0),
            (".20deg", 20.0),
        ] {
            name.set(method_id, amp_id);
            let mut result = Ok(());
            let ticks = window(|| {
                result = plan_jump(&disc, 0.0, deg(amp_deg), method, CAPACITY).map(|p| {
                    black_box(&p);
                });
            });
            match result {
                Ok(()) => b.report(name.as_str(), ticks, 1),
                Err(e) => b.fail(name.as_str(), e),
            }
        }
    }
    // Two axes, as the loop plans them (both axes, time-optimal).
    let galvo = Galvo::<f64>::default();
    let lsb = 1.0 / galvo.dac_x.codes_per_rad;
    let angles = |x_mm: f64, y_mm: f64| {
        galvo
            .geometry
            .ik(PointMm::new(x_mm, y_mm))
            .map(|a| [a.x_rad, a.y_rad])
    };
    let cases = [
        ("plan.xy.optimal.1lsb", Ok([0.0, 0.0]), Ok([lsb, lsb])),
        (
            "plan.xy.optimal.160mm",
            angles(-80.0, -80.0),
            angles(80.0, 80.0),
        ),
    ];
    for (id, from, to) in cases {
        let (Ok(from), Ok(to)) = (from, to) else {
            b.fail(id, "ik");
            continue;
        };
        let mut result = Ok(());
        let ticks = window(|| {
            result = plan_xy_jump(
                &disc,
                &disc,
                from,
                to,
                Method::TimeOptimal,
                JumpSync::Independent,
                CAPACITY,
            )
            .map(|p| {
                black_box(&p);
            });
        });
        match result {
            Ok(()) => b.report(id, ticks, 1),
            Err(e) => b.fail(id, e),
        }
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    let mut out = Out::new();
    let _ = writeln!(out, "panic");
    out.flush();
    semihosting::exit(false)
}
