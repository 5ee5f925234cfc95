//! Following a popped block's planned profile at a fixed period (the
//! gimbal's stream).

use super::block::LookaheadBlock;

/// Follows a popped block's planned profile at a fixed period: where the
/// motion is along the block and how fast it goes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SpeedCursor {
    /// The block followed.
    pub block: LookaheadBlock,
    /// Distance done along it.
    pub done: f64,
    /// Speed now, length/s.
    pub speed: f64,
}

impl SpeedCursor {
    /// At the start of `block`, at its planned entry speed.
    pub fn start(block: LookaheadBlock) -> Self {
        Self {
            block,
            done: 0.0,
            speed: block.entry_speed,
        }
    }

    /// Advances by `dt_s` seconds with the cruise speed scaled by `scale`
    /// (feed override, > 0) — or braking at the limit when `hold` — and
    /// returns the distance by which the step ran past the block's end
    /// (`None` while inside it). The speed never rises or falls faster
    /// than the block's acceleration; it brakes on the discrete braking
    /// curve to the block's planned exit speed.
    pub fn advance(&mut self, dt_s: f64, scale: f64, hold: bool) -> Option<f64> {
        let b = self.block;
        let left = (b.length - self.done).max(0.0);
        let next = if hold {
            (self.speed - b.accel * dt_s).max(0.0)
        } else {
            let cruise = b.nominal_speed * scale.max(0.0);
            let up = (self.speed + b.accel * dt_s).min(cruise);
            let down = (self.speed - b.accel * dt_s).max(0.0);
            let mut brake = self.braking_speed(dt_s, left);
            if 0.5 * (self.speed + b.exit_speed) * dt_s >= left {
                // The end is reached within this period anyway: at most
                // at the exit speed.
                brake = brake.max(b.exit_speed);
            }
            up.min(brake).max(down)
        };
        let step = 0.5 * (self.speed + next) * dt_s;
        self.speed = next;
        if step >= left {
            self.done = b.length;
            return Some(step - left);
        }
        self.done += step;
        None
    }

    /// The highest speed at the end of a period of `dt_s` from which the
    /// block can still end at its exit speed with `left` to go (the
    /// discrete braking curve: v'² + a·dt·v' ≤ e² + 2·a·left − a·dt·v).
    fn braking_speed(&self, dt_s: f64, left: f64) -> f64 {
        let (a, e) = (self.block.accel, self.block.exit_speed);
        let adt = a * dt_s;
        let rhs = e * e + 2.0 * a * left - adt * self.speed;
        if rhs <= 0.0 {
            return 0.0;
        }
        0.5 * (libm::sqrt(adt * adt + 4.0 * rhs) - adt)
    }

    /// Continues into `block` (the next one popped) at the speed reached,
    /// `overshoot` into it.
    pub fn continue_into(&mut self, block: LookaheadBlock, overshoot: f64) {
        *self = Self {
            block,
            done: crate::numeric::clamp(overshoot, 0.0, block.length),
            speed: self.speed,
        };
    }

    /// Whether a hold has come to rest here.
    pub fn is_at_rest(&self) -> bool {
        self.speed <= 0.0
    }

    /// Fraction (0..=1) of the block done.
    pub fn fraction(&self) -> f64 {
        if self.block.length > 0.0 {
            crate::numeric::clamp(self.done / self.block.length, 0.0, 1.0)
        } else {
            1.0
        }
    }
}
