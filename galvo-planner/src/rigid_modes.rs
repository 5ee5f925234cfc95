//! The sampled rigid model in modal form, `f32`: what the single-precision
//! time-optimal planner ([`fast_optimal`](crate::fast_optimal)) needs of a
//! model, computed once when the model is discretised (part of
//! [`Discrete`](crate::model::Discrete)), and the small `f32` routines it is
//! built from. Below the model: it reads only the continuous `A` matrix.

use crate::linalg::{Matrix, at};

/// `e^z − 1` for `z ≤ 0.5` in `f32`, a few ulp: Taylor series near 0,
/// `2^k·e^r − 1` with `|r| ≤ ln2/2` otherwise. No `f64`, no libm.
pub(crate) fn expm1_f32(z: f32) -> f32 {
    if z.is_nan() {
        return z;
    }
    if z < -88.0 {
        return -1.0;
    }
    let series = |r: f32| -> f32 {
        // r + r²/2! + … + r⁹/9! (Horner); |r| ≤ 0.35: last term < 2e-11.
        let mut p = 1.0 / 362_880.0;
        p = p * r + 1.0 / 40_320.0;
        p = p * r + 1.0 / 5_040.0;
        p = p * r + 1.0 / 720.0;
        p = p * r + 1.0 / 120.0;
        p = p * r + 1.0 / 24.0;
        p = p * r + 1.0 / 6.0;
        p = p * r + 0.5;
        p = p * r + 1.0;
        p * r
    };
    if z > -0.35 && z < 0.35 {
        return series(z);
    }
    // z = k·ln2 + r, ln2 split in a high part exact in f32 and a low part.
    const LN2_HI: f32 = 0.693_145_75;
    const LN2_LO: f32 = 1.428_606_8e-6;
    const INV_LN2: f32 = core::f32::consts::LOG2_E;
    let kf = z * INV_LN2;
    // Round to nearest without libm (|kf| < 128).
    let k = if kf < 0.0 {
        (kf - 0.5) as i32
    } else {
        (kf + 0.5) as i32
    };
    let kf = k as f32;
    let r = (z - kf * LN2_HI) - kf * LN2_LO;
    let er = series(r) + 1.0;
    if k < -126 {
        return -1.0;
    }
    let scale = f32::from_bits(((k + 127) as u32) << 23);
    er * scale - 1.0
}

/// The larger of `a` and `b` (plain compare: `f32::max` is a library call
/// on the M4F); `b` when `a` is NaN.
#[inline(always)]
pub(crate) fn hi(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// The smaller of `a` and `b`; `b` when `a` is NaN.
#[inline(always)]
pub(crate) fn lo(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// One decaying mode of the sampled model: `λ = e^ℓ`, `ℓ = p·Ts < 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Mode {
    pub(crate) ell: f32,
    /// `λ − 1`.
    pub(crate) mu: f32,
}

impl Mode {
    /// `(G(x), λ^⌊x⌋)` for `x ≥ 0`.
    #[inline]
    pub(crate) fn g(&self, x: f32) -> (f32, f32) {
        let mut cache = PowerCache::EMPTY;
        self.g_cached(x, &mut cache)
    }

    /// [`g`](Self::g) reusing `λ^n − 1` when `x` is still in sample `n`
    /// (Newton's last steps stay in the same samples).
    #[inline]
    pub(crate) fn g_cached(&self, x: f32, cache: &mut PowerCache) -> (f32, f32) {
        let cell = x as i32; // x ≥ 0: truncation is floor
        let n = cell as f32;
        let f = x - n;
        let m = if cache.cell == cell {
            cache.pm1
        } else {
            let m = expm1_f32(n * self.ell);
            *cache = PowerCache { cell, pm1: m };
            m
        };
        (m / self.mu + f * (1.0 + m), 1.0 + m)
    }
}

/// `λ^n − 1` of the last sample `n` a point was in.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PowerCache {
    cell: i32,
    pm1: f32,
}

impl PowerCache {
    pub(crate) const EMPTY: Self = Self { cell: -1, pm1: 0.0 };
}

/// Smallest `|p·Ts|` of a mode the `f32` form handles: the rounding of the
/// mode sums grows as `ε/|ℓ|` (≈ 5e-6 of the speed and current scales at
/// this limit), and a mode that decays over hundreds of samples is nearly
/// a second integrator. The reference galvo has |ℓ| = 0.029 at Ts = 10 µs.
const MIN_ABS_ELL: f32 = 3.0e-3;

/// What the `f32` planner needs of a sampled rigid model, computed once
/// when the model is discretised (part of [`Discrete`]): the two decaying
/// modes and the integrator gain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RigidModes {
    pub(crate) modes: [Mode; 2],
    /// `Kt/(Ts·Umax)`: `M = D·m_per_rad` in samples of `Umax`.
    pub(crate) m_per_rad: f32,
    pub(crate) u_max_v: f32,
    pub(crate) ts_s: f32,
}

impl RigidModes {
    /// From the rigid model's continuous `A` (state `θ, ω, I`), torque
    /// constant (N·m/A), voltage limit (V) and sample period (s). `None`
    /// when the model does not have three states, its electrical poles are
    /// complex or too close for the modal form in `f32`, or a mode is too
    /// slow. (The caller checks that the model is the rigid one.)
    pub(crate) fn new<const S: usize>(
        a: &Matrix<S, S>,
        kt_nm_per_a: f64,
        u_max_v: f64,
        ts_s: f64,
    ) -> Option<Self> {
        if S != 3 {
            return None;
        }
        let get = |i: usize, j: usize| a.get(i).map_or(0.0, |row| at(row, j));
        // ω' = (Kt/J)·I, I' = −(Kt/L)·ω − (R/L)·I.
        let alpha = -(get(2, 2) as f32);
        let beta = -(get(1, 2) as f32) * (get(2, 1) as f32);
        let ts = ts_s as f32;
        let disc2 = alpha * alpha - 4.0 * beta;
        if !(alpha > 0.0 && beta > 0.0 && disc2 > 1e-2 * alpha * alpha) {
            return None;
        }
        let q = -0.5 * (alpha + libm::sqrtf(disc2));
        let (p1, p2) = (q, beta / q);
        let mode = |p: f32| {
            let ell = p * ts;
            Mode {
                ell,
                mu: expm1_f32(ell),
            }
        };
        let modes = [mode(p2), mode(p1)];
        let m_per_rad = (kt_nm_per_a / (ts_s * u_max_v)) as f32;
        let ok = modes
            .iter()
            .all(|m| m.ell < -MIN_ABS_ELL && m.ell > -80.0 && m.mu < 0.0)
            && m_per_rad.is_finite()
            && m_per_rad > 0.0;
        ok.then_some(Self {
            modes,
            m_per_rad,
            u_max_v: u_max_v as f32,
            ts_s: ts,
        })
    }
}
