//! The sampled `+,−,+` bang-bang input law of the time-optimal planners and
//! their diagnostics: below [`plan`](crate::plan), which stores the law, and
//! the two planners ([`optimal`](crate::optimal),
//! [`fast_optimal`](crate::fast_optimal)) that build it.

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

    /// Calls `f(k, u_k as f32)` for k = N−1, …, 0: the values of
    /// [`Self::u_v`] rounded to `f32`, with the saturated ones (all but
    /// the switch samples and the last) computed and rounded once, not
    /// per sample in soft-float `f64` (the M4F's cost).
    pub(crate) fn for_each_rev_f32(&self, mut f: impl FnMut(usize, f32)) {
        let high = (self.sign * self.u_max_v) as f32;
        let low = (-self.sign * self.u_max_v) as f32;
        for k in (0..self.n).rev() {
            let saturated = k + 1 != self.n
                && k != self.k1
                && k != self.k2
                && (k < self.k1 || k > self.k2 || (k > self.k1 && k < self.k2));
            let u = match saturated {
                true if k > self.k1 && k < self.k2 => low,
                true => high,
                false => self.u_v(k) as f32,
            };
            f(k, u);
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
}

/// The shape of an `f32` plan, as the single-precision planner solved it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FastShape {
    /// The 3-sample dead-beat input for the positive move, reversed
    /// (index 0 is the last sample), V.
    DeadBeat([f32; 3]),
    /// The sampled bang-bang: switch points counted from the end
    /// (`σ1 ≥ σ2 ≥ 1`, samples) and the last sample's value `w` in units
    /// of Umax, for the positive move.
    BangBang { sigma1: f32, sigma2: f32, w: f32 },
}

/// The input law of a plan from the single-precision planner
/// ([`fast_optimal`](crate::fast_optimal)), kept in the `f32` it was
/// solved in: planning does no soft-float `f64` work on the M4F. The
/// `f64` [`BangBang`] law, the inputs and the [`OptimalInfo`] are derived
/// from it when asked, bit for bit what the planner used to store.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FastLaw {
    /// Samples `N`.
    pub(crate) n: usize,
    /// The move is negative (every input's sign flipped).
    pub(crate) negative: bool,
    /// The continuous-time optimum's length `N*`, samples.
    pub(crate) n_star: f32,
    /// The continuous optimum's switch points from the end `(σ1, σ2)`,
    /// samples, when Newton found it.
    pub(crate) cont: Option<(f32, f32)>,
    /// Sample period, s.
    pub(crate) ts_s: f32,
    pub(crate) shape: FastShape,
}

impl FastLaw {
    fn sign(&self) -> f64 {
        if self.negative { -1.0 } else { 1.0 }
    }

    /// The dead-beat inputs in sample order, V (`None` for a bang-bang).
    pub(crate) fn dead_beat_u_v(&self) -> Option<[f64; 3]> {
        let FastShape::DeadBeat(u) = self.shape else {
            return None;
        };
        let sign = self.sign();
        Some(core::array::from_fn(|j| {
            sign * f64::from(*u.get(2 - j).unwrap_or(&0.0))
        }))
    }

    /// The `f64` bang-bang law (`None` for the dead-beat input);
    /// `u_max_v` the model's voltage limit, V.
    pub(crate) fn bang_bang(&self, u_max_v: f64) -> Option<BangBang> {
        let FastShape::BangBang { sigma1, sigma2, w } = self.shape else {
            return None;
        };
        let nf = self.n as f64;
        let (s1, s2) = (nf - f64::from(sigma1), nf - f64::from(sigma2));
        Some(BangBang::new(
            self.n,
            s1,
            s2,
            f64::from(w) * u_max_v,
            u_max_v,
            self.sign(),
        ))
    }

    /// Largest `|u_k|`, V: Umax for a bang-bang (`N ≥ 4` and `|w| ≤ 1`
    /// by construction: at most two switch samples, one saturated), the
    /// largest dead-beat input otherwise.
    pub(crate) fn peak_abs_u_v(&self, u_max_v: f64) -> f64 {
        match self.shape {
            FastShape::DeadBeat(u) => f64::from(u.iter().fold(0.0f32, |p, x| {
                let a = x.abs();
                if p > a { p } else { a }
            })),
            FastShape::BangBang { .. } => u_max_v,
        }
    }

    /// The planner's diagnostics; `u_max_v` the voltage limit, V.
    pub(crate) fn info(&self, u_max_v: f64) -> OptimalInfo {
        let ts = self.ts_s;
        let continuous = self.cont.map(|(sigma1, sigma2)| ContinuousOptimum {
            time_s: f64::from(self.n_star * ts),
            switches_s: (
                f64::from((self.n_star - sigma1) * ts),
                f64::from((self.n_star - sigma2) * ts),
            ),
        });
        let samples_lower_bound = if continuous.is_some() {
            let c = libm::ceilf(self.n_star - 1e-4);
            if c >= 1.0 { c as usize } else { 1 }
        } else {
            0
        };
        let mut info = OptimalInfo {
            structure: OptimalStructure::DeadBeat,
            continuous,
            samples_lower_bound,
            switch_samples: (0.0, 0.0),
            last_sample_v: 0.0,
            single_precision: true,
        };
        if let Some(bb) = self.bang_bang(u_max_v) {
            info.structure = OptimalStructure::BangBang;
            info.switch_samples = (bb.s1, bb.s2);
            info.last_sample_v = bb.sign * bb.v_last;
        }
        info
    }
}

/// A move the single-precision planner solved: from rest at `from_rad`
/// to rest at `to_rad` (rad) with `law`, or a hold at `from_rad` (`law`
/// `None`: nothing to move). A few words: the two-axis planner solves
/// both axes before it builds either plan, so no whole plan (~540 bytes)
/// passes through a `Result`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FastMove {
    pub(crate) from_rad: f64,
    pub(crate) to_rad: f64,
    pub(crate) law: Option<FastLaw>,
}
