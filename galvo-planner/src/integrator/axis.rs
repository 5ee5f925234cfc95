//! One axis of the integrator: its model, commanded state and queued
//! inputs (the module docs of [`super`] give the update, its cost and the
//! queueing rules).

use crate::error::Error;
use crate::linalg::{Matrix, Vector, at};
use crate::model::{Discrete, THETA};
use crate::plan::JumpPlan;
use kinematics_core::numeric::finite;

mod run;

#[derive(Debug, Clone, Copy, PartialEq)]
struct QueuedMove<const S: usize> {
    samples: usize,
    target: Vector<S>,
}

/// One axis: model, commanded state, queued inputs.
#[derive(Debug, Clone)]
pub struct Integrator<const S: usize, const CAP: usize, const Q: usize = 4> {
    a_minus_i: [[f32; S]; S],
    bd: [f32; S],
    ad64: Matrix<S, S>,
    bd64: Vector<S>,
    z: [f32; S],
    comp: [f32; S],
    ring: [f32; CAP],
    read: usize,
    queued: usize,
    moves: [QueuedMove<S>; Q],
    move_read: usize,
    move_count: usize,
    k_in_move: usize,
    end_state: Vector<S>,
    /// Which states are angles (θ, φ).
    rest_mask: [bool; S],
}

fn to_f32<const S: usize>(z: &Vector<S>) -> [f32; S] {
    core::array::from_fn(|i| at(z, i) as f32)
}

/// One sample of `Z += (Ad − I)·Z + Bd·u` with compensated (Kahan)
/// summation of the increment into `z`.
///
/// The three-state rigid model (what the galvo loop runs) goes through
/// `advance3`, written out as fixed multiply-adds: this function is
/// instantiated in the caller's crate, which the firmware builds for size
/// (its loops stay loops), while `advance3` is straight-line code.
#[inline(always)]
fn advance<const S: usize>(
    a_minus_i: &[[f32; S]; S],
    bd: &[f32; S],
    z: &mut [f32; S],
    comp: &mut [f32; S],
    u: f32,
) {
    // S == 3 (resolved at compile time): the fixed three-state kernel.
    if S == 3
        && let (Some([r0, r1, r2]), Some(b3), Some(z3), Some(c3)) = (
            a_minus_i.first_chunk::<3>(),
            bd.first_chunk::<3>(),
            z.first_chunk_mut::<3>(),
            comp.first_chunk_mut::<3>(),
        )
        && let (Some(r0), Some(r1), Some(r2)) = (
            r0.first_chunk::<3>(),
            r1.first_chunk::<3>(),
            r2.first_chunk::<3>(),
        )
    {
        advance3([r0, r1, r2], b3, z3, c3, u);
        return;
    }
    let z0 = *z;
    for (((zi, ci), row), b) in z
        .iter_mut()
        .zip(comp.iter_mut())
        .zip(a_minus_i.iter())
        .zip(bd.iter())
    {
        let mut inc = b * u;
        for (a, x) in row.iter().zip(z0.iter()) {
            inc += a * x;
        }
        kahan_add(zi, ci, inc);
    }
}

/// `x += inc` with the running compensation `c` (Kahan).
#[inline(always)]
fn kahan_add(x: &mut f32, c: &mut f32, inc: f32) {
    let y = inc - *c;
    let t = *x + y;
    *c = (t - *x) - y;
    *x = t;
}

/// [`advance`] for three states: 12 multiply-adds and 12 add/subs.
#[inline]
fn advance3(a: [&[f32; 3]; 3], b: &[f32; 3], z: &mut [f32; 3], c: &mut [f32; 3], u: f32) {
    let [z0, z1, z2] = *z;
    let [a0, a1, a2] = a;
    let inc = [
        b[0] * u + a0[0] * z0 + a0[1] * z1 + a0[2] * z2,
        b[1] * u + a1[0] * z0 + a1[1] * z1 + a1[2] * z2,
        b[2] * u + a2[0] * z0 + a2[1] * z1 + a2[2] * z2,
    ];
    let [x0, x1, x2] = z;
    let [c0, c1, c2] = c;
    kahan_add(x0, c0, inc[0]);
    kahan_add(x1, c1, inc[1]);
    kahan_add(x2, c2, inc[2]);
}

/// Relative tolerance for "the plan starts where the queue ends".
const CONTINUITY_TOL: f64 = 1e-9;

impl<const S: usize, const CAP: usize, const Q: usize> Integrator<S, CAP, Q> {
    /// A integrator at rest at `theta_rad` for the sampled model `disc`.
    pub fn new(disc: &Discrete<S>, theta_rad: f64) -> Result<Self, Error> {
        let theta_rad = finite(theta_rad, "theta_rad")?;
        let rest = disc.model().rest_state(theta_rad);
        let ad = disc.ad();
        let a_minus_i = core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                let a = ad.get(i).map_or(0.0, |row| at(row, j));
                (if i == j { a - 1.0 } else { a }) as f32
            })
        });
        Ok(Self {
            a_minus_i,
            bd: to_f32(disc.bd()),
            ad64: *ad,
            bd64: *disc.bd(),
            z: to_f32(&rest),
            comp: [0.0; S],
            ring: [0.0; CAP],
            read: 0,
            queued: 0,
            moves: [QueuedMove {
                samples: 0,
                target: rest,
            }; Q],
            move_read: 0,
            move_count: 0,
            k_in_move: 0,
            end_state: rest,
            rest_mask: *disc.model().position_states(),
        })
    }

    /// Checks whether `plan` could be queued now (same model, starts where
    /// the queue ends, room in the ring and the move list).
    pub fn check_queue(&self, plan: &JumpPlan<S>) -> Result<(), Error> {
        if plan.discrete().ad() != &self.ad64 || plan.discrete().bd() != &self.bd64 {
            return Err(Error::ModelMismatch);
        }
        let continuous = plan
            .start_state()
            .iter()
            .zip(self.end_state.iter())
            .all(|(a, b)| libm::fabs(a - b) <= CONTINUITY_TOL * (1.0 + libm::fabs(*b)));
        if !continuous {
            return Err(Error::DiscontinuousMove);
        }
        if plan.samples() > 0
            && (self.move_count >= Q || self.queued.saturating_add(plan.samples()) > CAP)
        {
            return Err(Error::QueueFull);
        }
        Ok(())
    }

    /// Appends `plan` behind the queued moves. Its voltages are copied into
    /// the ring (as `f32`); the plan itself is not kept.
    pub fn queue(&mut self, plan: &JumpPlan<S>) -> Result<(), Error> {
        self.enqueue(plan, true)
    }

    /// Appends `plan` like [`Self::queue`], for a move whose samples
    /// someone else computes (the same plan stepped from the same state,
    /// e.g. ahead of time): its inputs are not copied, and it is passed
    /// over with [`Self::skip`], not stepped.
    pub fn queue_skipped(&mut self, plan: &JumpPlan<S>) -> Result<(), Error> {
        self.enqueue(plan, false)
    }

    fn enqueue(&mut self, plan: &JumpPlan<S>, inputs: bool) -> Result<(), Error> {
        self.check_queue(plan)?;
        let n = plan.samples();
        if n == 0 {
            return Ok(());
        }
        let tail = (self.read + self.queued) % CAP;
        let ring = &mut self.ring;
        if inputs {
            plan.for_each_input_rev_f32(|k, u| {
                if let Some(slot) = ring.get_mut((tail + k) % CAP) {
                    *slot = u;
                }
            });
        }
        let slot = (self.move_read + self.move_count) % Q;
        if let Some(m) = self.moves.get_mut(slot) {
            *m = QueuedMove {
                samples: n,
                target: *plan.target_state(),
            };
        }
        self.move_count += 1;
        self.queued += n;
        self.end_state = *plan.target_state();
        Ok(())
    }

    /// Advances one sample period and returns the commanded motor angle θ
    /// (rad) at the new sample. Idle: returns the held angle.
    #[inline]
    pub fn step(&mut self) -> f32 {
        if self.move_count == 0 {
            return self.position_rad();
        }
        let u = self.ring.get(self.read).copied().unwrap_or(0.0);
        self.read = (self.read + 1) % CAP;
        self.queued = self.queued.saturating_sub(1);
        // Z += (Ad − I)·Z + Bd·u, with compensated summation.
        advance(&self.a_minus_i, &self.bd, &mut self.z, &mut self.comp, u);
        self.k_in_move += 1;
        let running = self.moves.get(self.move_read).map(|m| m.samples);
        if running.is_some_and(|samples| self.k_in_move >= samples)
            && let Some(m) = self.moves.get(self.move_read).copied()
        {
            self.land(&m.target);
        }
        self.position_rad()
    }

    /// The running move is over: land exactly on its planned target.
    fn land(&mut self, target: &Vector<S>) {
        self.z = to_f32(target);
        self.comp = [0.0; S];
        self.k_in_move = 0;
        self.move_read = (self.move_read + 1) % Q;
        self.move_count = self.move_count.saturating_sub(1);
    }

    /// Commanded motor angle now, rad.
    pub fn position_rad(&self) -> f32 {
        self.z.get(THETA).copied().unwrap_or(0.0)
    }
    /// Full commanded state now (θ, ω, I[, φ, ω_φ]).
    pub fn state(&self) -> &[f32; S] {
        &self.z
    }
    /// True when no move is running or queued (holding position).
    pub fn is_idle(&self) -> bool {
        self.move_count == 0
    }
    /// Queued samples left, including the rest of the running move.
    pub fn remaining_samples(&self) -> usize {
        self.queued
    }
    /// Free input slots in the ring.
    pub fn free_samples(&self) -> usize {
        CAP - self.queued
    }
    /// Moves queued, including the running one.
    pub fn queued_moves(&self) -> usize {
        self.move_count
    }
    /// The state where the last queued move ends (plan the next one from
    /// here).
    pub fn end_state(&self) -> &Vector<S> {
        &self.end_state
    }
    /// θ of [`end_state`](Self::end_state), rad.
    pub fn end_position_rad(&self) -> f64 {
        at(&self.end_state, THETA)
    }

    /// A placeholder of no model (all zero), to be [`reset`](Self::reset)
    /// in place: lets a big owner be built without an integrator
    /// temporary on the stack. Steps nothing useful until reset.
    pub const IDLE: Self = Self {
        a_minus_i: [[0.0; S]; S],
        bd: [0.0; S],
        ad64: [[0.0; S]; S],
        bd64: [0.0; S],
        z: [0.0; S],
        comp: [0.0; S],
        ring: [0.0; CAP],
        read: 0,
        queued: 0,
        moves: [QueuedMove {
            samples: 0,
            target: [0.0; S],
        }; Q],
        move_read: 0,
        move_count: 0,
        k_in_move: 0,
        end_state: [0.0; S],
        rest_mask: [false; S],
    };

    /// [`Self::new`] in place (nothing copied: the sample ring is a few KB):
    /// the model `disc`, at rest at `theta_rad`, queued moves dropped.
    /// Fails (changing nothing) for a non-finite `theta_rad`.
    pub fn reset(&mut self, disc: &Discrete<S>, theta_rad: f64) -> Result<(), Error> {
        let theta_rad = finite(theta_rad, "theta_rad")?;
        let rest = disc.model().rest_state(theta_rad);
        let ad = disc.ad();
        for (i, row) in self.a_minus_i.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                let a = ad.get(i).map_or(0.0, |r| at(r, j));
                *v = (if i == j { a - 1.0 } else { a }) as f32;
            }
        }
        self.bd = to_f32(disc.bd());
        self.ad64 = *ad;
        self.bd64 = *disc.bd();
        self.z = to_f32(&rest);
        self.comp = [0.0; S];
        self.ring.fill(0.0);
        self.read = 0;
        self.queued = 0;
        for m in &mut self.moves {
            *m = QueuedMove {
                samples: 0,
                target: rest,
            };
        }
        self.move_read = 0;
        self.move_count = 0;
        self.k_in_move = 0;
        self.end_state = rest;
        self.rest_mask = *disc.model().position_states();
        Ok(())
    }

    /// Re-seats an idle integrator at rest at `theta_rad` (e.g. where a marked
    /// path, which drives the mirrors directly, left them), so the next jump
    /// is planned and queued from there. Fails with
    /// [`Error::IntegratorBusy`] while a move is queued.
    pub fn hold_at(&mut self, theta_rad: f64) -> Result<(), Error> {
        let theta_rad = finite(theta_rad, "theta_rad")?;
        if !self.is_idle() {
            return Err(Error::IntegratorBusy);
        }
        let mut rest = self.end_state;
        for (i, v) in rest.iter_mut().enumerate() {
            *v = if self.position_state(i) {
                theta_rad
            } else {
                0.0
            };
        }
        self.z = to_f32(&rest);
        self.comp = [0.0; S];
        self.end_state = rest;
        Ok(())
    }

    /// Whether state `i` is an angle (equal to θ at rest).
    fn position_state(&self, i: usize) -> bool {
        self.rest_mask.get(i).copied().unwrap_or(false)
    }

    /// Drops the queued moves that have not started yet; the running move
    /// completes. Returns how many were dropped.
    pub fn clear_pending(&mut self) -> usize {
        if self.move_count <= 1 {
            return 0;
        }
        let dropped = self.move_count - 1;
        let remaining_in_current = self
            .moves
            .get(self.move_read)
            .map_or(0, |m| m.samples.saturating_sub(self.k_in_move));
        self.queued = remaining_in_current;
        self.move_count = 1;
        if let Some(m) = self.moves.get(self.move_read) {
            self.end_state = m.target;
        }
        dropped
    }
}
