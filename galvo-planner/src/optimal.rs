//! Time-optimal rest-to-rest planner for the rigid model, in `f64`.
//!
//! [`Method::TimeOptimal`](crate::jump::Method::TimeOptimal) plans with the
//! single-precision [`fast_optimal`](crate::fast_optimal) planner (same
//! plans, microseconds on the M4F); this one is its reference and its
//! fallback for the galvos the `f32` form does not cover.
//!
//! The rigid model has the eigenvalues 0, p1, p2 (real and negative for the
//! reference galvo: −2.9e3 and −12.7e3 1/s). For real eigenvalues the
//! continuous-time minimum-time control under `|U| ≤ Umax` is bang-bang with
//! at most two switches (Feldbaum): `+Umax` on `[0, t1)`, `−Umax` on
//! `[t1, t2)`, `+Umax` on `[t2, T)` for a positive move. On the sample grid
//! the planner keeps that structure:
//!
//! 1. **Continuous optimum** `(t1, t2, T)` by Newton's method on the three
//!    landing equations `θ(T) = D, ω(T) = 0, I(T) = 0`, using the model's
//!    closed-form step response, with continuation in the distance (start in
//!    the jerk-limited regime where `t1 = T/4, t2 = 3T/4` is accurate and grow
//!    the distance ×16 per stage, smaller strides after a failed stage). `T` is a lower bound for every ZOH input,
//!    so `N ≥ ⌈T/Ts⌉`.
//! 2. **Sampled bang-bang** for `N = ⌈T/Ts⌉ − 1, ⌈T/Ts⌉, …`: every sample is
//!    the average of a `+,−,+` signal with switch points `s1 ≤ s2` (in
//!    samples) — saturated except the two samples containing a switch — and
//!    the last sample is a free value `v`. The three unknowns `(s1, s2, v)`
//!    are solved exactly for the discrete landing equations (piecewise
//!    linear; Newton converges in a few steps). The first `N` with
//!    `|v| ≤ Umax` is the plan: it lands exactly and never exceeds `Umax`
//!    by construction.
//!
//! When `⌈T/Ts⌉ ≤ 3` (tiny moves) the unique 3-sample (dead-beat) input is
//! tried first. For a strongly underdamped coil (complex poles) the optimum
//! may need more switches; when no two-switch solution exists the planner
//! falls back to the fastest minimum-energy input
//! ([`OptimalStructure::MinEnergyFallback`]), so a valid request still gets
//! an exact, feasible plan.
//!
//! Cost: the closed-form response makes every evaluation two `expm1` (real
//! poles) and a few dozen flops, no matrix exponential and no buffer; a
//! 20° move takes ~5 continuation stages of a few Newton steps plus 1–2
//! sampled solves (≈ 17–25 µs on a desktop core, see the README).

use crate::error::{Error, clamp, finite};
use crate::jump::{InputLaw, JumpPlan, MethodKind, PlanInfo};
use crate::linalg::{Matrix, Vector, at, expm_and_integral, mat_vec, solve};
use crate::min_energy::{SeedConfig, min_energy_at};
use crate::model::{Discrete, ModelKind};

/// How a time-optimal plan was built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OptimalStructure {
    /// The unique 3-sample input (tiny moves).
    DeadBeat,
    /// Sampled `+,−,+` bang-bang with a free last sample (the normal case).
    BangBang,
    /// The two-switch structure does not exist for this galvo (strongly
    /// underdamped coil: complex poles) or was not found: the fastest
    /// minimum-energy input (bisection to 2⁻²⁴ of the bracket) is used
    /// instead. Feasible and exact, but not guaranteed time-optimal.
    MinEnergyFallback,
}

/// The continuous-time bang-bang optimum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContinuousOptimum {
    /// Minimum move time `T`, s: a lower bound for any input held constant
    /// over samples (valid as such when the poles are real).
    pub time_s: f64,
    /// Switching instants `(t1, t2)`, s.
    pub switches_s: (f64, f64),
}

/// Diagnostics of a time-optimal plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OptimalInfo {
    /// How the plan was built.
    pub structure: OptimalStructure,
    /// The continuous-time optimum, when it was found.
    pub continuous: Option<ContinuousOptimum>,
    /// `⌈T/Ts⌉` (0 when the continuous optimum is unknown).
    pub samples_lower_bound: usize,
    /// Sampled switch points `(s1, s2)` in samples (bang-bang only).
    pub switch_samples: (f64, f64),
    /// Voltage of the free last sample, V, signed (bang-bang only).
    pub last_sample_v: f64,
    /// Solved in single precision by
    /// [`plan_time_optimal_fast`](crate::fast_optimal::plan_time_optimal_fast)
    /// (microseconds on the M4F) rather than by this module's `f64` solver.
    pub single_precision: bool,
}

/// Halvings of the minimum-energy fallback.
const FALLBACK_HALVINGS: u32 = 24;

/// The sampled bang-bang input law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BangBang {
    n: usize,
    s1: f64,
    s2: f64,
    /// Last sample's value for the positive move, V.
    v_last: f64,
    u_max_v: f64,
    sign: f64,
    /// Samples `k < k1` are `+Umax`, `k1 ≤ k < k2` (after the samples that
    /// contain a switch) … see [`BangBang::u_v`]; integer cells precomputed
    /// so that saturated samples cost no floating-point work.
    k1: usize,
    k2: usize,
}

fn overlap(a: f64, b: f64, c: f64, d: f64) -> f64 {
    (b.min(d) - a.max(c)).max(0.0)
}

/// `⌊x⌋` for `0 ≤ x`, as a sample index.
fn cell(x: f64) -> usize {
    if x > 0.0 { x as usize } else { 0 }
}

impl BangBang {
    /// `+Umax` on `[0, s1)`, `−Umax` on `[s1, s2)`, `+Umax` on
    /// `[s2, n−1)` (samples, `0 ≤ s1 ≤ s2 ≤ n−1`), sample averages, last
    /// sample `v_last`; all times `sign`.
    pub(crate) fn new(n: usize, s1: f64, s2: f64, v_last: f64, u_max_v: f64, sign: f64) -> Self {
        Self {
            n,
            s1,
            s2,
            v_last,
            u_max_v,
            sign,
            k1: cell(s1),
            k2: cell(s2),
        }
    }

    /// Voltage of sample `k`.
    pub(crate) fn u_v(&self, k: usize) -> f64 {
        if k + 1 == self.n {
            return self.sign * self.v_last;
        }
        if k >= self.n {
            return 0.0;
        }
        // Saturated samples: no switch inside.
        if k < self.k1 {
            return self.sign * self.u_max_v;
        }
        if k > self.k1 && k < self.k2 {
            return -self.sign * self.u_max_v;
        }
        if k > self.k2 {
            return self.sign * self.u_max_v;
        }
        let (a, b) = (k as f64, k as f64 + 1.0);
        let end = (self.n - 1) as f64;
        let avg = overlap(a, b, 0.0, self.s1) - overlap(a, b, self.s1, self.s2)
            + overlap(a, b, self.s2, end);
        self.sign * self.u_max_v * avg
    }

    /// Largest `|u_k|` over the plan, V, from the few samples that are not
    /// saturated (no pass over the samples).
    pub(crate) fn peak_abs_u_v(&self) -> f64 {
        let last = self.n.saturating_sub(1);
        if last >= 3 && libm::fabs(self.v_last) <= self.u_max_v {
            // At most two of the first n−1 ≥ 3 samples hold a switch: one
            // is saturated, and nothing exceeds Umax.
            return self.u_max_v;
        }
        let saturated = (0..last).len()
            > usize::from(self.k1 < last) + usize::from(self.k2 < last && self.k2 != self.k1);
        let mut peak = if saturated { self.u_max_v } else { 0.0 };
        for k in [self.k1, self.k2, last] {
            if k < self.n {
                peak = peak.max(libm::fabs(self.u_v(k)));
            }
        }
        peak
    }
}

// ---- closed-form response of the rigid model ------------------------------

#[derive(Debug, Clone, Copy, PartialEq)]
struct C {
    re: f64,
    im: f64,
}

impl C {
    const fn new(re: f64, im: f64) -> Self {
        Self { re, im }
    }
    fn add(self, o: C) -> C {
        C::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: C) -> C {
        C::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: C) -> C {
        C::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn scale(self, s: f64) -> C {
        C::new(self.re * s, self.im * s)
    }
    fn div(self, o: C) -> C {
        let d = o.re * o.re + o.im * o.im;
        C::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    fn abs(self) -> f64 {
        libm::hypot(self.re, self.im)
    }
    /// `e^z − 1`, accurate for small |z|.
    fn exp_m1(self) -> C {
        let s = libm::sin(0.5 * self.im);
        C::new(
            libm::expm1(self.re) * libm::cos(self.im) - 2.0 * s * s,
            libm::exp(self.re) * libm::sin(self.im),
        )
    }
}

/// `E1(z) = (e^z − 1)/z` and `E2(z) = (e^z − 1 − z)/z²`.
fn e12(z: C) -> (C, C) {
    if z.abs() < 0.5 {
        // Series: E1 = Σ z^k/(k+1)!, E2 = Σ z^k/(k+2)!; 20 terms ≪ 1e-17.
        let mut e1 = C::new(0.0, 0.0);
        let mut e2 = C::new(0.0, 0.0);
        let mut zk = C::new(1.0, 0.0);
        let mut fact1 = 1.0; // (k+1)!
        for k in 0..20u32 {
            let f1 = fact1;
            let f2 = fact1 * f64::from(k + 2);
            e1 = e1.add(zk.scale(1.0 / f1));
            e2 = e2.add(zk.scale(1.0 / f2));
            zk = zk.mul(z);
            fact1 = f2;
        }
        (e1, e2)
    } else {
        let em1 = z.exp_m1();
        let e1 = em1.div(z);
        let e2 = em1.sub(z).div(z.mul(z));
        (e1, e2)
    }
}

/// Impulse response `ψ(τ) = e^{Aτ}·B` and step response `Ψ(τ) = ∫₀^τ ψ` of
/// the rigid model. With `c = Kt/J` and the roots p1, p2 of
/// `s² + (R/L)s + Kt²/(J·L)`, writing `Δ[f] = (f(p1) − f(p2))/(p1 − p2)`:
/// `ψ = (c/L)·(Δ[τE1(pτ)], Δ[e^{pτ}], Δ[p·e^{pτ}]/c)`,
/// `Ψ = (c/L)·(Δ[τ²E2(pτ)], Δ[τE1(pτ)], Δ[e^{pτ}]/c)`.
/// Falls back to the matrix exponential when the roots nearly coincide.
#[derive(Debug, Clone, Copy)]
struct RigidResponse {
    c: f64,
    inv_l: f64,
    p1: C,
    p2: C,
    a: Matrix<3, 3>,
    b: Vector<3>,
    closed_form: bool,
}

impl RigidResponse {
    fn new(kt: f64, j: f64, l: f64, r: f64, a: Matrix<3, 3>, b: Vector<3>) -> Self {
        let alpha = r / l;
        let beta = kt * kt / (j * l);
        let disc = alpha * alpha - 4.0 * beta;
        let (p1, p2) = if disc >= 0.0 {
            // Numerically stable real roots.
            let q = -0.5 * (alpha + libm::sqrt(disc));
            (C::new(q, 0.0), C::new(beta / q, 0.0))
        } else {
            let w = 0.5 * libm::sqrt(-disc);
            (C::new(-0.5 * alpha, w), C::new(-0.5 * alpha, -w))
        };
        let sep = p1.sub(p2).abs();
        let closed_form = sep > 1e-4 * p1.abs().max(p2.abs()) && sep.is_finite();
        Self {
            c: kt / j,
            inv_l: 1.0 / l,
            p1,
            p2,
            a,
            b,
            closed_form,
        }
    }

    /// `(τ·E1(pτ), τ²·E2(pτ), e^{pτ}, p·e^{pτ})` for one root.
    fn root_terms(p: C, tau: f64) -> [C; 4] {
        let z = p.scale(tau);
        let (e1, e2) = e12(z);
        // e^z = 1 + z·E1(z) (exact identity, no second exponential).
        let ez = C::new(1.0, 0.0).add(z.mul(e1));
        [e1.scale(tau), e2.scale(tau * tau), ez, p.mul(ez)]
    }

    /// Real-root version of [`root_terms`](Self::root_terms).
    fn root_terms_real(p: f64, tau: f64) -> [f64; 4] {
        let z = p * tau;
        let (e1, e2) = if libm::fabs(z) < 0.5 {
            // E1 = Σ z^k/(k+1)!, E2 = Σ z^k/(k+2)!; 18 terms ≪ 1e-17.
            let (mut e1, mut e2, mut zk, mut f1) = (0.0, 0.0, 1.0, 1.0);
            for k in 0..18u32 {
                let f2 = f1 * f64::from(k + 2);
                e1 += zk / f1;
                e2 += zk / f2;
                zk *= z;
                f1 = f2;
            }
            (e1, e2)
        } else {
            let em1 = libm::expm1(z);
            (em1 / z, (em1 - z) / (z * z))
        };
        let ez = 1.0 + z * e1;
        [e1 * tau, e2 * tau * tau, ez, p * ez]
    }

    /// `(ψ(τ), Ψ(τ))`.
    fn response(&self, tau: f64) -> (Vector<3>, Vector<3>) {
        if !self.closed_form {
            let (e, phi) = expm_and_integral(&self.a, tau);
            return (mat_vec(&e, &self.b), mat_vec(&phi, &self.b));
        }
        // Divided differences Δ[f] = (f(p1) − f(p2))/(p1 − p2).
        let [t1, t2, ex, pex] = if self.p1.im == 0.0 && self.p2.im == 0.0 {
            let a = Self::root_terms_real(self.p1.re, tau);
            let b = Self::root_terms_real(self.p2.re, tau);
            let den = self.p1.re - self.p2.re;
            core::array::from_fn(|i| (at(&a, i) - at(&b, i)) / den)
        } else {
            let a = Self::root_terms(self.p1, tau);
            let b = Self::root_terms(self.p2, tau);
            let den = self.p1.sub(self.p2);
            core::array::from_fn(|i| match (a.get(i), b.get(i)) {
                (Some(x), Some(y)) => x.sub(*y).div(den).re,
                _ => 0.0,
            })
        };
        let k = self.c * self.inv_l;
        (
            [k * t1, k * ex, self.inv_l * pex],
            [k * t2, k * t1, self.inv_l * ex],
        )
    }

    fn step_response(&self, tau: f64) -> Vector<3> {
        if tau <= 0.0 {
            [0.0; 3]
        } else {
            self.response(tau).1
        }
    }

    fn impulse_response(&self, tau: f64) -> Vector<3> {
        if tau < 0.0 {
            [0.0; 3]
        } else {
            self.response(tau).0
        }
    }
}

// ---- a small damped Newton solver for three unknowns ----------------------

struct Newton3 {
    /// Residual scales (θ, ω, I).
    scales: Vector<3>,
    tol: f64,
    max_iter: u32,
}

impl Newton3 {
    fn merit(&self, r: &Vector<3>) -> f64 {
        r.iter()
            .zip(self.scales.iter())
            .map(|(x, s)| {
                let y = x / s;
                y * y
            })
            .sum()
    }

    /// Solves `r(x) = 0`. `eval` returns the residual and the Jacobian
    /// (columns = partial derivatives), `project` maps onto the feasible
    /// domain, `nudge` moves off a singular point.
    fn solve(
        &self,
        mut x: Vector<3>,
        eval: impl Fn(&Vector<3>) -> (Vector<3>, Matrix<3, 3>),
        project: impl Fn(Vector<3>) -> Vector<3>,
        nudge: impl Fn(Vector<3>) -> Vector<3>,
    ) -> Option<Vector<3>> {
        x = project(x);
        for _ in 0..self.max_iter {
            let (r, jac) = eval(&x);
            let m = self.merit(&r);
            if !m.is_finite() {
                return None;
            }
            if m <= self.tol * self.tol {
                return Some(x);
            }
            let Some((dx, _)) = solve(jac, [-at(&r, 0), -at(&r, 1), -at(&r, 2)]) else {
                x = project(nudge(x));
                continue;
            };
            let mut step = 1.0;
            let mut accepted = false;
            for _ in 0..40 {
                let cand = project(core::array::from_fn(|i| at(&x, i) + step * at(&dx, i)));
                let (rc, _) = eval(&cand);
                let mc = self.merit(&rc);
                if mc.is_finite() && mc < m * (1.0 - 1e-4 * step) {
                    x = cand;
                    accepted = true;
                    break;
                }
                step *= 0.5;
            }
            if !accepted {
                // Stuck on a kink or bound: try moving off it once.
                let moved = project(nudge(x));
                if moved == x {
                    return None;
                }
                x = moved;
            }
        }
        None
    }
}

/// Distance growth per continuation stage (smaller after a failed stage).
const STAGE_RATIO: f64 = 16.0;

/// Continuous-time optimum `(t1, t2, T)` for a positive distance `d`.
fn continuous_optimum(
    resp: &RigidResponse,
    u_max: f64,
    d: f64,
    omega_scale: f64,
    current_scale: f64,
    jerk: f64,
    tau_e: f64,
) -> Option<Vector<3>> {
    let solve_at = |dist: f64, guess: Vector<3>| -> Option<Vector<3>> {
        let newton = Newton3 {
            scales: [dist, omega_scale, current_scale],
            tol: 1e-12,
            max_iter: 60,
        };
        let eval = |x: &Vector<3>| {
            let [t1, t2, t] = *x;
            let (g_t, s_t) = resp.response(t);
            let g1 = resp.impulse_response(t - t1);
            let g2 = resp.impulse_response(t - t2);
            let s1 = resp.step_response(t - t1);
            let s2 = resp.step_response(t - t2);
            let target = [dist, 0.0, 0.0];
            let r: Vector<3> = core::array::from_fn(|i| {
                u_max * (at(&s_t, i) - 2.0 * at(&s1, i) + 2.0 * at(&s2, i)) - at(&target, i)
            });
            let jac: Matrix<3, 3> = core::array::from_fn(|i| {
                [
                    2.0 * u_max * at(&g1, i),
                    -2.0 * u_max * at(&g2, i),
                    u_max * (at(&g_t, i) - 2.0 * at(&g1, i) + 2.0 * at(&g2, i)),
                ]
            });
            (r, jac)
        };
        let project = |x: Vector<3>| -> Vector<3> {
            let t = x[2].max(1e-12);
            let t1 = clamp(x[0], 0.0, t);
            let t2 = clamp(x[1], t1, t);
            [t1, t2, t]
        };
        let nudge = |x: Vector<3>| -> Vector<3> { [x[0] * 0.9, x[1], x[2] * 1.05] };
        newton.solve(guess, eval, project, nudge)
    };
    // Jerk-limited (triple integrator) solution: D = jerk·T³/32, t1 = T/4,
    // t2 = 3T/4; accurate while T ≪ L/R.
    let triple = |dist: f64| -> Vector<3> {
        let t = libm::cbrt(32.0 * dist / jerk);
        [0.25 * t, 0.75 * t, t]
    };
    let d0 = jerk * (0.1 * tau_e) * (0.1 * tau_e) * (0.1 * tau_e) / 32.0;
    if d <= d0 {
        return solve_at(d, triple(d));
    }
    let mut cur_d = d0;
    let mut cur = solve_at(d0, triple(d0))?;
    let mut ratio = STAGE_RATIO;
    let mut failures = 0;
    while cur_d < d {
        let next_d = (cur_d * ratio).min(d);
        let scale = libm::sqrt(next_d / cur_d);
        let guess = [cur[0] * scale, cur[1] * scale, cur[2] * scale];
        match solve_at(next_d, guess) {
            Some(x) => {
                cur = x;
                cur_d = next_d;
                ratio = STAGE_RATIO;
            }
            None => {
                failures += 1;
                if failures > 12 {
                    return None;
                }
                ratio = 1.0 + 0.5 * (ratio - 1.0);
            }
        }
    }
    Some(cur)
}

/// Sampled bang-bang with a free last sample at exactly `n` samples:
/// `(s1, s2, v)` or `None` if there is no such input with `|v| ≤ Umax`.
fn sampled_bang_bang(
    resp: &RigidResponse,
    ts: f64,
    u_max: f64,
    d: f64,
    n: usize,
    guess: (f64, f64),
    scales: Vector<3>,
) -> Option<Vector<3>> {
    if n < 4 {
        return None;
    }
    let last = (n - 1) as f64;
    // Ψ at q samples.
    let big_s = |q: usize| resp.step_response(q as f64 * ts);
    // R(s): response at sample n of an averaged unit step starting at s,
    // and its derivative −g_q.
    let r_of = |s: f64| -> (Vector<3>, Vector<3>) {
        let m = clamp(libm::floor(s), 0.0, (n - 1) as f64);
        let f = s - m;
        let q = n - 1 - m as usize;
        let (hi, lo) = (big_s(q + 1), big_s(q));
        let r = core::array::from_fn(|i| (1.0 - f) * at(&hi, i) + f * at(&lo, i));
        // Derivative in cell min(m, n−2).
        let qd = if m as usize >= n - 1 { 1 } else { q };
        let (hd, ld) = (big_s(qd + 1), big_s(qd));
        let g = core::array::from_fn(|i| at(&hd, i) - at(&ld, i));
        (r, g)
    };
    let r0 = big_s(n);
    let g0 = big_s(1);
    let eval = |x: &Vector<3>| {
        let [s1, s2, v] = *x;
        let (r1, g1) = r_of(s1);
        let (r2, g2) = r_of(s2);
        let target = [d, 0.0, 0.0];
        let r: Vector<3> = core::array::from_fn(|i| {
            u_max * (at(&r0, i) - 2.0 * at(&r1, i) + 2.0 * at(&r2, i) - at(&g0, i)) + v * at(&g0, i)
                - at(&target, i)
        });
        let jac: Matrix<3, 3> = core::array::from_fn(|i| {
            [
                2.0 * u_max * at(&g1, i),
                -2.0 * u_max * at(&g2, i),
                at(&g0, i),
            ]
        });
        (r, jac)
    };
    let project = |x: Vector<3>| -> Vector<3> {
        let s1 = clamp(x[0], 0.0, last);
        let s2 = clamp(x[1], s1, last);
        [s1, s2, x[2]]
    };
    // Singular when both switches share a sample: push the second one into
    // the next sample.
    let nudge = |x: Vector<3>| -> Vector<3> {
        let s2 = (libm::floor(x[0]) + 1.0).min(last).max(x[1]);
        if s2 > x[1] {
            [x[0], s2, x[2]]
        } else {
            [(x[0] - 0.5).max(0.0), x[1], x[2]]
        }
    };
    let newton = Newton3 {
        scales,
        tol: 1e-12,
        max_iter: 60,
    };
    let g = (clamp(guess.0, 0.0, last), clamp(guess.1, 0.0, last));
    let x = newton.solve([g.0, g.1, 0.0], eval, project, nudge)?;
    if libm::fabs(x[2]) <= u_max {
        Some(x)
    } else {
        None
    }
}

/// A checked rest-to-rest move of the rigid model (both time-optimal
/// planners start here).
pub(crate) enum RigidMove<const S: usize> {
    /// Start and target are the same angle: hold.
    Hold,
    /// A move to plan.
    Move {
        /// Start angle, rad (finite).
        from_rad: f64,
        /// Target angle, rad (finite).
        to_rad: f64,
        /// Rest state at the start.
        z0: Vector<S>,
        /// Rest state at the target.
        z1: Vector<S>,
        /// Usable stepper capacity, samples.
        capacity: usize,
    },
}

/// Checks a time-optimal request: a rigid model, finite angles.
///
/// Errors: [`Error::UnsupportedModel`], [`Error::NonFinite`].
pub(crate) fn rigid_move<const S: usize>(
    disc: &Discrete<S>,
    from_rad: f64,
    to_rad: f64,
    capacity: usize,
) -> Result<RigidMove<S>, Error> {
    if S != 3 || disc.model().kind() != ModelKind::Rigid {
        return Err(Error::UnsupportedModel);
    }
    let from_rad = finite("from_rad", from_rad)?;
    let to_rad = finite("to_rad", to_rad)?;
    if from_rad == to_rad {
        return Ok(RigidMove::Hold);
    }
    let model = disc.model();
    Ok(RigidMove::Move {
        from_rad,
        to_rad,
        z0: model.rest_state(from_rad),
        z1: model.rest_state(to_rad),
        capacity: crate::jump::effective_capacity(capacity),
    })
}

/// How many sample counts above the continuous bound are tried.
const EXTRA_SAMPLE_COUNTS: usize = 12;

/// Time-optimal rest-to-rest move from `from_rad` to `to_rad` (rigid model
/// only). See the module documentation.
pub fn plan_time_optimal<const S: usize>(
    disc: &Discrete<S>,
    from_rad: f64,
    to_rad: f64,
    capacity: usize,
) -> Result<JumpPlan<S>, Error> {
    let RigidMove::Move {
        from_rad,
        to_rad,
        z0,
        z1,
        capacity,
    } = rigid_move(disc, from_rad, to_rad, capacity)?
    else {
        return Ok(JumpPlan::hold(disc, disc.model().rest_state(from_rad)));
    };
    let model = disc.model();
    let delta = to_rad - from_rad;
    let (d, sign) = (libm::fabs(delta), if delta < 0.0 { -1.0 } else { 1.0 });
    let drive = model.drive();
    let u_max = disc.u_max_v();
    let ts = disc.ts_s();
    let a3: Matrix<3, 3> = core::array::from_fn(|i| {
        core::array::from_fn(|j| model.a().get(i).map_or(0.0, |row| at(row, j)))
    });
    let b3: Vector<3> = core::array::from_fn(|i| at(model.b(), i));
    let resp = RigidResponse::new(
        drive.kt_nm_per_a,
        drive.j_kg_m2,
        drive.l_h,
        drive.r_ohm,
        a3,
        b3,
    );
    let omega_scale = u_max / drive.kt_nm_per_a;
    let current_scale = u_max / drive.r_ohm;
    let jerk = drive.kt_nm_per_a * u_max / (drive.j_kg_m2 * drive.l_h);
    let tau_e = drive.l_h / drive.r_ohm;
    let cont = continuous_optimum(&resp, u_max, d, omega_scale, current_scale, jerk, tau_e);
    let n_lo = cont.map_or(1, |[_, _, t_c]| {
        crate::min_energy::samples_for(t_c, ts).max(1)
    });
    let mut info = OptimalInfo {
        structure: OptimalStructure::BangBang,
        continuous: cont.map(|[t1, t2, t_c]| ContinuousOptimum {
            time_s: t_c,
            switches_s: (t1, t2),
        }),
        samples_lower_bound: if cont.is_some() { n_lo } else { 0 },
        switch_samples: (0.0, 0.0),
        last_sample_v: 0.0,
        single_precision: false,
    };
    if n_lo <= S {
        if S > capacity {
            return Err(Error::CapacityExceeded {
                needed: S,
                capacity,
            });
        }
        if let Some(sol) = min_energy_at(disc, &z0, &z1, S, 2)
            && sol.max_abs_u_v <= u_max
        {
            info.structure = OptimalStructure::DeadBeat;
            return Ok(JumpPlan::new(
                disc,
                z0,
                z1,
                S,
                InputLaw::MinEnergy { lambda: sol.lambda },
                MethodKind::TimeOptimal,
                PlanInfo::Optimal(info),
            ));
        }
    }
    if let Some([t1, t2, _]) = cont {
        let scales = [d, omega_scale, current_scale];
        let first = n_lo.saturating_sub(1).max(S + 1);
        for n in first..first.saturating_add(EXTRA_SAMPLE_COUNTS) {
            if n > capacity {
                return Err(Error::CapacityExceeded {
                    needed: n,
                    capacity,
                });
            }
            let guess = (t1 / ts, t2 / ts);
            if let Some([s1, s2, v]) = sampled_bang_bang(&resp, ts, u_max, d, n, guess, scales) {
                info.switch_samples = (s1, s2);
                info.last_sample_v = sign * v;
                let law = BangBang::new(n, s1, s2, v, u_max, sign);
                return Ok(JumpPlan::new(
                    disc,
                    z0,
                    z1,
                    n,
                    InputLaw::BangBang(law),
                    MethodKind::TimeOptimal,
                    PlanInfo::Optimal(info),
                ));
            }
        }
    }
    // No two-switch solution: the fastest minimum-energy input instead.
    let cfg = SeedConfig {
        p: FALLBACK_HALVINGS,
        bracket_s: None,
    };
    let plan = crate::min_energy::plan_seed(disc, &z0, &z1, cfg, capacity)?;
    info.structure = OptimalStructure::MinEnergyFallback;
    Ok(plan.relabel(MethodKind::TimeOptimal, PlanInfo::Optimal(info)))
}

#[cfg(test)]
mod tests;
