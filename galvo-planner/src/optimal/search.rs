//! The two searches of the `f64` time-optimal planner: the continuous-time
//! optimum (continuation in the distance) and the sampled bang-bang at a
//! given sample count, both by a small damped Newton solver.

use super::response::RigidResponse;
use crate::linalg::{Matrix, Vector, at, solve};
use kinematics_core::numeric::clamp;

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
pub(super) fn continuous_optimum(
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
pub(super) fn sampled_bang_bang(
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
