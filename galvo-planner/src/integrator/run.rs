//! Runs of samples: the refill asks for many samples at once, and within
//! one move they need no per-sample bookkeeping (move list, landing
//! check), so they run as a tight loop with the model and the state in
//! registers. Same operations in the same order as [`Integrator::step`]:
//! bit for bit the same angles (tests).

use super::{Integrator, advance};
use crate::model::THETA;

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
}
