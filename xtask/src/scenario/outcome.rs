//! What a board did in a scenario, reduced to what the checks read.

use crate::qemu::BoardEvent;

/// What a board did in a scenario, board-neutral.
#[derive(Debug, Clone, Default)]
pub struct Outcome {
    /// Which board (for messages).
    pub board: &'static str,
    /// The console transcript: `> command` lines and the device's lines.
    pub transcript: Vec<String>,
    /// Closing replies that were `error: …`.
    pub error_replies: usize,
    /// Unsolicited notices (`[…]`).
    pub notices: Vec<String>,
    /// Laser switches: (board µs, lit).
    pub laser_events: Vec<(u64, bool)>,
    /// Laser-deciding sequencer events: (board µs, event).
    pub events: Vec<(u64, BoardEvent)>,
    /// The script was sent completely and every reply read.
    pub script_done: bool,
    /// The sequencer was idle at the end.
    pub idle_at_end: bool,
    /// Boots (one more per `@reset`).
    pub boots: usize,
    /// Board time at the end, µs.
    pub end_us: u64,
}
