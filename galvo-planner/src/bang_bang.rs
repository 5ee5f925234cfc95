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
