//! The baseline position profiles themselves (T-curve, S-curve): their
//! limits from the model, their kinematics and the sample-averaged
//! inverse-dynamics voltage. Below [`plan`](crate::plan), which stores a
//! profile as an input law; the planner is [`profile`](crate::profile),
//! whose documentation derives the limits and the voltage.

use crate::error::{Error, positive};
use crate::model::Drive;
use kinematics_core::numeric::finite;

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
        positive(self.v_max_rad_s, "v_max_rad_s")?;
        positive(self.a_max_rad_s2, "a_max_rad_s2")?;
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
        let d = libm::fabs(finite(distance_rad, "distance_rad")?);
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
