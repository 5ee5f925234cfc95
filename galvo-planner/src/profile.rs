//! Baseline position profiles: trapezoidal (T-curve) and jerk-limited
//! S-curve, rest to rest, with limits derived from the model, and the
//! voltage each needs (inverse dynamics) to be followed by the galvo.
//!
//! ## Limits from the model
//!
//! For the rigid model (and the flexible one with `J = Jm + Jl`), following a
//! profile θ(t) needs `I = J·θ''/Kt` and
//! `U = Kt·θ' + (R·J/Kt)·θ'' + (L·J/Kt)·θ'''` (back-EMF + resistive +
//! inductive terms). The baselines share `Umax` among these terms so that
//! the continuous-time voltage cannot exceed it:
//!
//! * **T-curve**: `v_max = (Umax/2)/Kt` (half the back-EMF-limited no-load
//!   speed) and `a_max = Kt·(Umax/2)/(R·J)` (half the stall-current
//!   acceleration) — the textbook motor-curve limits. The inductance is
//!   ignored, so the step changes of acceleration need voltage spikes of
//!   `L·J·Δa/(Kt·Ts)` on the sample grid: this baseline exceeds `Umax`.
//! * **S-curve**: `v_max = (Umax/3)/Kt`, `a_max = Kt·(Umax/3)/(R·J)`,
//!   `j_max = Kt·(Umax/3)/(L·J)`: each term gets a third, so
//!   `|U| ≤ Umax` holds at every instant.
//!
//! ## Voltage on the sample grid
//!
//! The input held over sample k is the average of the continuous inverse
//! dynamics over `[k·Ts, (k+1)·Ts)`, which is exact in closed form:
//! `(Kt·Δθ + (R·J/Kt)·Δω + (L·J/Kt)·Δα)/Ts` with left limits of α (so an
//! acceleration step inside the sample contributes its impulse). The ZOH
//! model driven by these averages ends close to, but not exactly on, the
//! target; a minimum-norm correction `Γᵀ·λ` (the same machinery as the seed
//! planner) makes it land exactly.

use crate::error::Error;
use crate::jump::{InputLaw, JumpPlan, MethodKind, PlanInfo};
use crate::linalg::{mat_vec, vec_sub};
use crate::min_energy::{gramian, solve};
use crate::model::{Discrete, Drive};

/// Which baseline profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfileKind {
    /// Trapezoidal velocity (infinite jerk).
    Trapezoid,
    /// Jerk-limited, 7 phases.
    SCurve,
}

/// Kinematic limits of a baseline profile (rad, s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileLimits {
    /// Speed limit, rad/s.
    pub v_max_rad_s: f64,
    /// Acceleration limit, rad/s².
    pub a_max_rad_s2: f64,
    /// Jerk limit, rad/s³ (`f64::INFINITY` for the trapezoid).
    pub j_max_rad_s3: f64,
}

impl ProfileLimits {
    /// The limits described in the module documentation.
    pub fn from_drive(kind: ProfileKind, drive: &Drive, u_max_v: f64) -> Self {
        let Drive {
            kt_nm_per_a: kt,
            j_kg_m2: j,
            l_h: l,
            r_ohm: r,
        } = *drive;
        match kind {
            ProfileKind::Trapezoid => Self {
                v_max_rad_s: 0.5 * u_max_v / kt,
                a_max_rad_s2: kt * 0.5 * u_max_v / (r * j),
                j_max_rad_s3: f64::INFINITY,
            },
            ProfileKind::SCurve => Self {
                v_max_rad_s: u_max_v / 3.0 / kt,
                a_max_rad_s2: kt * (u_max_v / 3.0) / (r * j),
                j_max_rad_s3: kt * (u_max_v / 3.0) / (l * j),
            },
        }
    }

    fn validate(&self) -> Result<(), Error> {
        crate::error::positive("v_max_rad_s", self.v_max_rad_s)?;
        crate::error::positive("a_max_rad_s2", self.a_max_rad_s2)?;
        if self.j_max_rad_s3.is_nan() || self.j_max_rad_s3 <= 0.0 {
            return Err(Error::NotPositive {
                name: "j_max_rad_s3",
                value: self.j_max_rad_s3,
            });
        }
        Ok(())
    }
}

/// A symmetric rest-to-rest profile (the "double S" with equal
/// acceleration and deceleration phases; the trapezoid is the case
/// `t_jerk_s = 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    /// Which shape.
    pub kind: ProfileKind,
    /// The limits it was built with.
    pub limits: ProfileLimits,
    /// Signed distance, rad.
    pub distance_rad: f64,
    /// Duration of each jerk phase, s (0 for the trapezoid).
    pub t_jerk_s: f64,
    /// Duration of the acceleration phase (including its jerk phases), s.
    pub t_accel_s: f64,
    /// Duration of the constant-speed phase, s.
    pub t_cruise_s: f64,
    /// Peak speed reached, rad/s (unsigned).
    pub v_peak_rad_s: f64,
    /// Peak acceleration reached, rad/s² (unsigned).
    pub a_peak_rad_s2: f64,
}

impl Profile {
    /// Builds the fastest symmetric profile of `kind` covering
    /// `distance_rad` within `limits`.
    pub fn new(kind: ProfileKind, distance_rad: f64, limits: ProfileLimits) -> Result<Self, Error> {
        limits.validate()?;
        let d = libm::fabs(crate::error::finite("distance_rad", distance_rad)?);
        let (v, a) = (limits.v_max_rad_s, limits.a_max_rad_s2);
        let j = match kind {
            ProfileKind::Trapezoid => f64::INFINITY,
            ProfileKind::SCurve => limits.j_max_rad_s3,
        };
        // Acceleration phase reaching peak speed vp: (t_jerk, t_accel).
        let phase = |vp: f64| -> (f64, f64) {
            if j.is_infinite() {
                (0.0, vp / a)
            } else if vp * j >= a * a {
                (a / j, a / j + vp / a)
            } else {
                let tj = libm::sqrt(vp / j);
                (tj, 2.0 * tj)
            }
        };
        // The acceleration phase covers vp·t_accel/2, so a move without
        // cruise covers vp·t_accel.
        let (tj_v, ta_v) = phase(v);
        let (vp, tj, ta, tv) = if v * ta_v <= d {
            (v, tj_v, ta_v, (d - v * ta_v) / v)
        } else {
            let vp = if j.is_infinite() {
                libm::sqrt(d * a)
            } else {
                // a reached: vp²/a + vp·a/j = d.
                let b = a / j;
                let vp_a = 0.5 * a * (-b + libm::sqrt(b * b + 4.0 * d / a));
                if vp_a * j >= a * a {
                    vp_a
                } else {
                    // a not reached: 2·vp·√(vp/j) = d.
                    libm::pow(0.5 * d * libm::sqrt(j), 2.0 / 3.0)
                }
            };
            let (tj, ta) = phase(vp);
            (vp, tj, ta, 0.0)
        };
        let a_peak = match kind {
            ProfileKind::Trapezoid if d > 0.0 => a,
            ProfileKind::Trapezoid => 0.0,
            ProfileKind::SCurve => j * tj,
        };
        Ok(Self {
            kind,
            limits,
            distance_rad,
            t_jerk_s: tj,
            t_accel_s: ta,
            t_cruise_s: tv,
            v_peak_rad_s: vp,
            a_peak_rad_s2: a_peak,
        })
    }

    /// Total duration, s.
    pub fn duration_s(&self) -> f64 {
        2.0 * self.t_accel_s + self.t_cruise_s
    }

    /// Acceleration phase (unsigned, τ ∈ [0, t_accel]) with left limits of
    /// the acceleration: (position, speed, acceleration).
    fn accel_phase(&self, tau: f64) -> (f64, f64, f64) {
        let (tj, ta, ap, vp) = (
            self.t_jerk_s,
            self.t_accel_s,
            self.a_peak_rad_s2,
            self.v_peak_rad_s,
        );
        let j = if tj > 0.0 { ap / tj } else { 0.0 };
        if tj > 0.0 && tau <= tj {
            (j * tau * tau * tau / 6.0, 0.5 * j * tau * tau, j * tau)
        } else if tau <= ta - tj {
            let t = tau - tj;
            let (p1, v1) = (j * tj * tj * tj / 6.0, 0.5 * ap * tj);
            (p1 + v1 * t + 0.5 * ap * t * t, v1 + ap * t, ap)
        } else {
            let r = ta - tau;
            (
                0.5 * vp * ta - vp * r + j * r * r * r / 6.0,
                vp - 0.5 * j * r * r,
                j * r,
            )
        }
    }

    /// (position from start, speed, acceleration) at time `t_s`, signed,
    /// with left limits of the acceleration. Zero before the start; the full
    /// distance with zero speed after the end.
    pub fn eval(&self, t_s: f64) -> (f64, f64, f64) {
        let sign = if self.distance_rad < 0.0 { -1.0 } else { 1.0 };
        let d = libm::fabs(self.distance_rad);
        let ta = self.t_accel_s;
        let total = self.duration_s();
        let (p, v, a) = if t_s <= 0.0 {
            (0.0, 0.0, 0.0)
        } else if t_s <= ta {
            self.accel_phase(t_s)
        } else if t_s <= ta + self.t_cruise_s {
            (
                0.5 * self.v_peak_rad_s * ta + self.v_peak_rad_s * (t_s - ta),
                self.v_peak_rad_s,
                0.0,
            )
        } else if t_s <= total {
            let (p, v, a) = self.accel_phase(total - t_s);
            (d - p, v, -a)
        } else {
            (d, 0.0, 0.0)
        };
        (sign * p, sign * v, sign * a)
    }

    /// Continuous inverse-dynamics voltage at `t_s` (excluding the impulses
    /// at acceleration steps), V.
    pub fn voltage_v(&self, drive: &Drive, t_s: f64) -> f64 {
        // Jerk from the phase structure.
        let (_, v, a) = self.eval(t_s);
        let tj = self.t_jerk_s;
        let jerk = if tj > 0.0 {
            let j = self.a_peak_rad_s2 / tj;
            let (ta, tc) = (self.t_accel_s, self.t_cruise_s);
            let total = self.duration_s();
            let sign = if self.distance_rad < 0.0 { -1.0 } else { 1.0 };
            let s = if t_s <= 0.0 || t_s > total {
                0.0
            } else if t_s <= tj {
                1.0
            } else if t_s <= ta - tj {
                0.0
            } else if t_s <= ta {
                -1.0
            } else if t_s <= ta + tc {
                0.0
            } else if t_s <= ta + tc + tj {
                -1.0
            } else if t_s <= total - tj {
                0.0
            } else {
                1.0
            };
            sign * s * j
        } else {
            0.0
        };
        let Drive {
            kt_nm_per_a: kt,
            j_kg_m2: jm,
            l_h: l,
            r_ohm: r,
        } = *drive;
        kt * v + r * jm / kt * a + l * jm / kt * jerk
    }

    /// Average inverse-dynamics voltage over sample `k` (see the module
    /// documentation), V.
    pub fn average_u_v(&self, drive: &Drive, ts_s: f64, k: usize) -> f64 {
        let t0 = k as f64 * ts_s;
        let t1 = t0 + ts_s;
        let (p0, v0, a0) = self.eval(t0);
        let (p1, v1, a1) = self.eval(t1);
        let Drive {
            kt_nm_per_a: kt,
            j_kg_m2: j,
            l_h: l,
            r_ohm: r,
        } = *drive;
        (kt * (p1 - p0) + r * j / kt * (v1 - v0) + l * j / kt * (a1 - a0)) / ts_s
    }
}

/// Plans a baseline jump: the profile, its sample-averaged inverse-dynamics
/// voltage and the minimum-norm landing correction. `limits: None` uses
/// [`ProfileLimits::from_drive`].
pub fn plan_profile<const S: usize>(
    disc: &Discrete<S>,
    from_rad: f64,
    to_rad: f64,
    kind: ProfileKind,
    limits: Option<ProfileLimits>,
    capacity: usize,
) -> Result<JumpPlan<S>, Error> {
    let from_rad = crate::error::finite("from_rad", from_rad)?;
    let to_rad = crate::error::finite("to_rad", to_rad)?;
    let z0 = disc.model().rest_state(from_rad);
    let z1 = disc.model().rest_state(to_rad);
    if from_rad == to_rad {
        return Ok(JumpPlan::hold(disc, z0));
    }
    let capacity = crate::jump::effective_capacity(capacity);
    let drive = *disc.model().drive();
    let limits = limits.unwrap_or_else(|| ProfileLimits::from_drive(kind, &drive, disc.u_max_v()));
    let profile = Profile::new(kind, to_rad - from_rad, limits)?;
    let ts = disc.ts_s();
    // Sample k covers [kTs, (k+1)Ts); the last one must contain the end
    // (and its acceleration step), hence floor + 1.
    let steps = libm::floor(profile.duration_s() / ts) + 1.0;
    if steps.is_nan() || steps >= capacity as f64 + 1.0 {
        return Err(Error::CapacityExceeded {
            needed: if steps >= usize::MAX as f64 {
                usize::MAX
            } else {
                steps as usize
            },
            capacity,
        });
    }
    let n_profile = (steps as usize).max(S);
    // The landing correction normally works over the profile's own samples;
    // when the sampled model is nearly uncontrollable over so few samples
    // (near-pathological sampling, tiny moves), give it up to 2·S more
    // samples of zero profile voltage at the end.
    let mut found = None;
    for n in n_profile..n_profile.saturating_add(2 * S + 1) {
        if n > capacity {
            return Err(Error::CapacityExceeded {
                needed: n,
                capacity,
            });
        }
        // Where the averaged voltages alone would land.
        let (an, _) = disc.power(n);
        let mut reached = mat_vec(&an, &z0);
        let mut g = *disc.bd();
        for j in 0..n {
            let u = profile.average_u_v(&drive, ts, n - 1 - j);
            for (r, gi) in reached.iter_mut().zip(g.iter()) {
                *r += gi * u;
            }
            g = mat_vec(disc.ad(), &g);
        }
        let d = vec_sub(&z1, &reached);
        let w = gramian(disc, n);
        let offset = |k: usize| profile.average_u_v(&drive, ts, k);
        if let Some(sol) = solve(disc, &w, &d, n, 2, &offset) {
            found = Some((n, sol));
            break;
        }
    }
    let (n, sol) = found.ok_or(Error::NotReachable { samples: n_profile })?;
    let method = match kind {
        ProfileKind::Trapezoid => MethodKind::TCurve,
        ProfileKind::SCurve => MethodKind::SCurve,
    };
    Ok(JumpPlan::new(
        disc,
        z0,
        z1,
        n,
        InputLaw::Profile {
            profile,
            lambda: sol.lambda,
        },
        method,
        PlanInfo::Profile(profile),
    ))
}

#[cfg(test)]
mod tests;
