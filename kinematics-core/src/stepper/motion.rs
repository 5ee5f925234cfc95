//! Limits and errors shared by the stepper planner, segment prep and step
//! generator.

/// One requested move: signed microsteps per axis (pan, tilt) and its
/// limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepMove {
    /// Signed microsteps to move, `[pan, tilt]`.
    pub steps: [i32; 2],
    /// Cruise rate, step events per second (dominant axis, steps/s).
    pub nominal_rate_steps_per_s: f64,
    /// Acceleration limit, step events per second² (steps/s²).
    pub accel_steps_per_s2: f64,
}

/// Lowest accepted nominal rate, steps/s: keeps every step interval
/// (≤ 1 s at cruise, ≤ √2 s from or to rest) inside a `u32` timer period.
pub const MIN_RATE_STEPS_PER_S: f64 = 1.0;
/// Highest accepted nominal rate, steps/s.
pub const MAX_RATE_STEPS_PER_S: f64 = 1.0e6;
/// Lowest accepted acceleration, steps/s².
pub const MIN_ACCEL_STEPS_PER_S2: f64 = 1.0;
/// Highest accepted acceleration, steps/s².
pub const MAX_ACCEL_STEPS_PER_S2: f64 = 1.0e9;
/// Most steps one block may have on an axis (keeps the step generator's
/// Bresenham counters inside `u32`).
pub const MAX_BLOCK_STEPS: u32 = 1 << 30;
/// Highest accepted step-timer frequency, Hz.
pub const MAX_TIMER_HZ: u32 = 100_000_000;

/// Why a move or a motion setting was refused. Nothing changes on error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionError {
    /// Nominal rate not finite or outside
    /// [`MIN_RATE_STEPS_PER_S`]..=[`MAX_RATE_STEPS_PER_S`].
    InvalidRate,
    /// Acceleration not finite or outside
    /// [`MIN_ACCEL_STEPS_PER_S2`]..=[`MAX_ACCEL_STEPS_PER_S2`].
    InvalidAccel,
    /// Junction deviation not finite or negative.
    InvalidJunctionDeviation,
    /// More than [`MAX_BLOCK_STEPS`] steps on an axis.
    MoveTooLong,
    /// The planner queue is full; try again once a block has left.
    QueueFull,
    /// Timer frequency 0 or above [`MAX_TIMER_HZ`], or a segment length
    /// not finite or outside 0.1 ms..=100 ms.
    InvalidTiming,
}

/// Checks a move's rate, acceleration and length; returns its step-event
/// count (the larger of the axes' `|steps|`, 0 for no motion).
///
/// Errors: [`MotionError::InvalidRate`], [`MotionError::InvalidAccel`],
/// [`MotionError::MoveTooLong`].
pub fn validate_move(mv: &StepMove) -> Result<u32, MotionError> {
    let rate = mv.nominal_rate_steps_per_s;
    if !(MIN_RATE_STEPS_PER_S..=MAX_RATE_STEPS_PER_S).contains(&rate) {
        return Err(MotionError::InvalidRate);
    }
    let accel = mv.accel_steps_per_s2;
    if !(MIN_ACCEL_STEPS_PER_S2..=MAX_ACCEL_STEPS_PER_S2).contains(&accel) {
        return Err(MotionError::InvalidAccel);
    }
    let events = mv.steps[0].unsigned_abs().max(mv.steps[1].unsigned_abs());
    if events > MAX_BLOCK_STEPS {
        return Err(MotionError::MoveTooLong);
    }
    Ok(events)
}
