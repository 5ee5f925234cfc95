//! What the checks find and the limits they hold the run to.

use std::fmt;

use crate::executor::LONG_STEP_NS;

/// Time after a stop (fault, button, underrun, …) within which every
/// laser must be dark, µs.
pub const DARK_WITHIN_US: u64 = 1_000;

/// Longest firmware task step (poll), ns of CPU time.
pub const MAX_STEP_NS: u64 = LONG_STEP_NS;

/// Stop reasons after which a laser may stay lit: a pattern that
/// completed has its last laser-off delay in the DAC's buffer already.
pub(super) const STOPS_THAT_ARE_NOT_SHUTDOWNS: &[&str] = &["pattern complete"];

/// Which invariant was broken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ViolationKind {
    /// (a) A laser lit more than 1 ms after a stop, fault, button press or
    /// underrun was processed.
    LitAfterStop,
    /// (b) The galvo laser lit while the mirrors jumped.
    LitGalvoJump,
    /// (b) The gimbal laser lit while travelling to a run's first point.
    LitTravel,
    /// (b) In `laser dwell` mode the gimbal laser lit without a confirmed
    /// arrival, or while a servo was truly outside the deadband.
    LitWithoutArrival,
    /// (c) A line without exactly one closing reply, a reply without a
    /// line, or a cut/glued line.
    Replies,
    /// (d) A firmware task step longer than 1 ms of CPU time.
    LongStep,
    /// (e) A lit G-code sample off the commanded path.
    OffPath,
    /// (f) A G-code motion not ended within its bound.
    LateMotion,
    /// (g) A laser lit while the interlock was open or the key off, before
    /// the emission indicator's delay, or without a reset since.
    LitWithoutControls,
    /// (h) A lit sample of a `pattern`, `goto` or `grid` run off its
    /// figure.
    OffFigure,
}

impl ViolationKind {
    /// Short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            ViolationKind::LitAfterStop => "lit-after-stop",
            ViolationKind::LitGalvoJump => "lit-galvo-jump",
            ViolationKind::LitTravel => "lit-travel",
            ViolationKind::LitWithoutArrival => "lit-without-arrival",
            ViolationKind::Replies => "replies",
            ViolationKind::LongStep => "long-step",
            ViolationKind::OffPath => "off-path",
            ViolationKind::LateMotion => "late-motion",
            ViolationKind::LitWithoutControls => "lit-without-controls",
            ViolationKind::OffFigure => "off-figure",
        }
    }
}

/// One breach of an invariant.
#[derive(Debug, Clone, PartialEq)]
pub struct Violation {
    /// Which invariant.
    pub kind: ViolationKind,
    /// Simulated time where it starts, µs.
    pub t_us: u64,
    /// What happened, for people.
    pub detail: String,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:>11.3} ms  {:<19}  {}",
            self.t_us as f64 / 1000.0,
            self.kind.name(),
            self.detail
        )
    }
}
