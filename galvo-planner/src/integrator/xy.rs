//! Both mirror axes stepped together.

use super::axis::Integrator;
use crate::error::Error;
use crate::model::Discrete;
use crate::plan::XyJump;
use kinematics_core::numeric::finite;

/// Both mirror axes of a galvo scanner, stepped together.
#[derive(Debug, Clone)]
pub struct XyIntegrator<const S: usize, const CAP: usize, const Q: usize = 4> {
    /// X mirror.
    pub x: Integrator<S, CAP, Q>,
    /// Y mirror.
    pub y: Integrator<S, CAP, Q>,
}

impl<const S: usize, const CAP: usize, const Q: usize> XyIntegrator<S, CAP, Q> {
    /// Both axes at rest at `theta_rad = [θx, θy]`.
    pub fn new(
        disc_x: &Discrete<S>,
        disc_y: &Discrete<S>,
        theta_rad: [f64; 2],
    ) -> Result<Self, Error> {
        let [tx, ty] = theta_rad;
        Ok(Self {
            x: Integrator::new(disc_x, tx)?,
            y: Integrator::new(disc_y, ty)?,
        })
    }

    /// Both axes [`Integrator::IDLE`]: reset before use.
    pub const IDLE: Self = Self {
        x: Integrator::IDLE,
        y: Integrator::IDLE,
    };

    /// [`Self::new`] in place (see [`Integrator::reset`]); fails, changing
    /// nothing, for a non-finite angle.
    pub fn reset(
        &mut self,
        disc_x: &Discrete<S>,
        disc_y: &Discrete<S>,
        theta_rad: [f64; 2],
    ) -> Result<(), Error> {
        let [tx, ty] = theta_rad;
        finite(tx, "theta_rad")?;
        finite(ty, "theta_rad")?;
        self.x.reset(disc_x, tx)?;
        self.y.reset(disc_y, ty)
    }

    /// Queues both axes of a jump, or neither.
    pub fn queue_jump(&mut self, jump: &XyJump<S>) -> Result<(), Error> {
        self.x.check_queue(&jump.x)?;
        self.y.check_queue(&jump.y)?;
        self.x.queue(&jump.x)?;
        self.y.queue(&jump.y)
    }

    /// Queues both axes of a jump whose samples someone else computes
    /// (see [`Integrator::queue_skipped`]), or neither.
    pub fn queue_jump_skipped(&mut self, jump: &XyJump<S>) -> Result<(), Error> {
        self.x.check_queue(&jump.x)?;
        self.y.check_queue(&jump.y)?;
        self.x.queue_skipped(&jump.x)?;
        self.y.queue_skipped(&jump.y)
    }

    /// Passes over `n` samples of both axes ([`Integrator::skip`]).
    pub fn skip(&mut self, n: usize) {
        self.x.skip(n);
        self.y.skip(n);
    }

    /// One sample of both axes: `[θx, θy]`, rad.
    #[inline]
    pub fn step(&mut self) -> [f32; 2] {
        [self.x.step(), self.y.step()]
    }

    /// Fills a block of `[θx, θy]` samples: what as many [`Self::step`]
    /// calls return, bit for bit, each axis as runs of tight loops
    /// ([`Integrator::fill_each`]).
    #[inline]
    pub fn fill(&mut self, out: &mut [[f32; 2]]) {
        let n = out.len();
        for axis in 0..2 {
            let integrator = if axis == 0 { &mut self.x } else { &mut self.y };
            integrator.fill_each(n, |i, theta| {
                if let Some(o) = out.get_mut(i).and_then(|o| o.get_mut(axis)) {
                    *o = theta;
                }
            });
        }
    }

    /// Samples until both axes hold position.
    pub fn remaining_samples(&self) -> usize {
        self.x.remaining_samples().max(self.y.remaining_samples())
    }

    /// True when both axes hold position.
    pub fn is_idle(&self) -> bool {
        self.x.is_idle() && self.y.is_idle()
    }

    /// Re-seats both idle axes at rest at `theta_rad = [θx, θy]` (see
    /// [`Integrator::hold_at`]); neither moves if one is busy.
    pub fn hold_at(&mut self, theta_rad: [f64; 2]) -> Result<(), Error> {
        if !self.is_idle() {
            return Err(Error::IntegratorBusy);
        }
        let [tx, ty] = theta_rad;
        finite(tx, "theta_rad")?;
        finite(ty, "theta_rad")?;
        self.x.hold_at(tx)?;
        self.y.hold_at(ty)
    }

    /// Where the queued jumps end, `[θx, θy]`, rad.
    pub fn end_position_rad(&self) -> [f64; 2] {
        [self.x.end_position_rad(), self.y.end_position_rad()]
    }
}
