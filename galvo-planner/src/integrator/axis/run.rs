//! Runs of samples: the refill asks for many samples at once, and within
//! one move they need no per-sample bookkeeping (move list, landing
//! check), so they run as a tight loop with the model and the state in
//! registers. Same operations in the same order as [`Integrator::step`]:
//! bit for bit the same angles (tests).

use super::{Integrator, advance, to_f32};
use crate::error::Error;
use crate::model::THETA;
use crate::plan::JumpPlan;

impl<const S: usize, const CAP: usize, const Q: usize> Integrator<S, CAP, Q> {
    /// Fills `out` with the commanded angle (rad) of the next `out.len()`
    /// samples: what as many [`Self::step`] calls return, bit for bit.
    #[inline]
    pub fn fill(&mut self, out: &mut [f32]) {
        let n = out.len();
        self.fill_each(n, |i, theta| {
            if let Some(o) = out.get_mut(i) {
                *o = theta;
            }
        });
    }

    /// Steps `n` samples, handing each sample's index (0..n) and
    /// commanded angle (rad) to `put`: what `n` [`Self::step`] calls
    /// return, bit for bit. Each move's samples before its last run as a
    /// tight loop; its last (the landing on the planned target) and an
    /// idle hold go through [`Self::step`] / [`Self::position_rad`].
    #[inline(always)]
    pub fn fill_each(&mut self, n: usize, mut put: impl FnMut(usize, f32)) {
        let mut i = 0;
        while i < n {
            let left_in_move = self
                .moves
                .get(self.move_read)
                .filter(|_| self.move_count > 0)
                .map(|m| m.samples.saturating_sub(self.k_in_move));
            let Some(left) = left_in_move else {
                // Idle: the held angle, unchanged.
                let theta = self.position_rad();
                (i..n).for_each(|k| put(k, theta));
                return;
            };
            let run = left.saturating_sub(1).min(n - i);
            if run > 0 {
                let (a, b) = (self.a_minus_i, self.bd);
                let (mut z, mut c) = (self.z, self.comp);
                let mut read = self.read;
                for k in i..i + run {
                    let u = self.ring.get(read).copied().unwrap_or(0.0);
                    read = (read + 1) % CAP;
                    advance(&a, &b, &mut z, &mut c, u);
                    put(k, z.get(THETA).copied().unwrap_or(0.0));
                }
                self.z = z;
                self.comp = c;
                self.read = read;
                self.queued = self.queued.saturating_sub(run);
                self.k_in_move += run;
                i += run;
            }
            if i < n {
                // The move's last sample: it lands.
                put(i, self.step());
                i += 1;
            }
        }
    }

    /// Passes over `n` samples without computing them (moves queued with
    /// [`Self::queue_skipped`]): the queue's bookkeeping moves on, and a
    /// move whose last sample is passed lands on its target as
    /// [`Self::step`] would. Mid-move the state is not tracked (the
    /// position reads the move's start) until the move lands.
    pub fn skip(&mut self, n: usize) {
        let mut left = n;
        while left > 0 && self.move_count > 0 {
            let Some(m) = self.moves.get(self.move_read).copied() else {
                return;
            };
            let k = m.samples.saturating_sub(self.k_in_move).min(left).max(1);
            self.read = (self.read + k) % CAP;
            self.queued = self.queued.saturating_sub(k);
            self.k_in_move += k;
            left -= k.min(left);
            if self.k_in_move >= m.samples {
                self.land(&m.target);
            }
        }
    }

    /// The commanded angle (rad) of every sample of `plan` stepped from
    /// rest at its start with this integrator's model, into
    /// `out[..plan.samples()]`: what an integrator holding at that state
    /// steps for it, bit for bit (the same `f32` update; the last sample
    /// lands on the target), without a ring, a move list or an integrator
    /// of its own. Returns the samples.
    ///
    /// Errors: [`Error::ModelMismatch`] for another model,
    /// [`Error::QueueFull`] when `out` is too short.
    pub fn plan_angles(&self, plan: &JumpPlan<S>, out: &mut [f32]) -> Result<usize, Error> {
        if plan.discrete().ad() != &self.ad64 || plan.discrete().bd() != &self.bd64 {
            return Err(Error::ModelMismatch);
        }
        let n = plan.samples();
        let out = out.get_mut(..n).ok_or(Error::QueueFull)?;
        // The inputs first, then each replaced by its sample's angle.
        plan.for_each_input_rev_f32(|k, u| {
            if let Some(slot) = out.get_mut(k) {
                *slot = u;
            }
        });
        let (a, b) = (self.a_minus_i, self.bd);
        let mut z = to_f32(plan.start_state());
        let mut c = [0.0f32; S];
        for slot in out.iter_mut() {
            advance(&a, &b, &mut z, &mut c, *slot);
            *slot = z.get(THETA).copied().unwrap_or(0.0);
        }
        if let Some(last) = out.last_mut() {
            // Landed exactly on the planned target.
            *last = to_f32(plan.target_state())
                .get(THETA)
                .copied()
                .unwrap_or(0.0);
        }
        Ok(n)
    }
}
