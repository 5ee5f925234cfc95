//! A block of the look-ahead queue, shared by the planner and its speed
//! cursor.

/// A block of the queue with its planned speeds (caller's units) and the
/// caller's data.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LookaheadBlock<T = ()> {
    /// Length (> 0; 0 for a stop pushed by [`Lookahead::push_stop`](super::Lookahead::push_stop)).
    pub length: f64,
    /// Cruise speed (> 0), length/s.
    pub nominal_speed: f64,
    /// Acceleration limit (> 0), length/s².
    pub accel: f64,
    /// Highest entry speed the junction with the previous block allows
    /// (0 for the first block after rest), length/s.
    pub max_entry_speed: f64,
    /// Planned entry speed, length/s.
    pub entry_speed: f64,
    /// Planned exit speed (set when the block leaves the queue: the next
    /// block's entry speed, or 0 when it is the last), length/s.
    pub exit_speed: f64,
    /// The caller's data of the block (what it moves, where).
    pub data: T,
}
