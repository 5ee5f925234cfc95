//! A run (a pattern or a goto) point by point: aim → servo move → arrival
//! → dwell → next point, next pass, or the end.

use crate::domain::{GridPattern, PathCursor, Pattern, Target};
use crate::status::Phase;
use embassy_time::Instant;

/// What a command starts.
#[derive(Debug, Clone, Copy)]
pub(super) enum Start {
    /// A goto or grid target, held until the next command.
    Goto(Target),
    /// A pattern, repeated until stopped unless `once`.
    Pattern {
        /// What runs.
        pattern: Pattern,
        /// A single pass.
        once: bool,
    },
}

/// What a run does, and where it is in its figure.
#[derive(Debug, Clone, Copy)]
#[allow(clippy::large_enum_variant)] // No heap: held in the core's state.
pub(super) enum RunKind {
    /// A goto or grid target, held until the next command.
    Goto(Target),
    /// A grid pattern, point `index` looked up in O(1).
    Grid {
        /// Which grid pattern.
        pattern: GridPattern,
        /// A single pass.
        once: bool,
    },
    /// A path the gimbal (with or without the galvo) draws point by
    /// point, `cursor` at the current point.
    Path {
        /// What runs.
        pattern: Pattern,
        /// A single pass.
        once: bool,
        /// The interpolator at the current point of this pass (O(1) next).
        cursor: PathCursor,
    },
    /// A path the stepper traces segment by segment: point 0 is the
    /// stroke's start, point `k` its `k`-th segment's end (lines and arcs
    /// exact, not the point-by-point interpolation).
    Traced {
        /// What runs.
        pattern: Pattern,
        /// A single pass.
        once: bool,
    },
    /// A path the galvo alone marks, one job per pass.
    Marked {
        /// What runs.
        pattern: Pattern,
        /// A single pass.
        once: bool,
    },
}

impl RunKind {
    /// The pattern that runs (`None`: a goto).
    pub(super) fn pattern(&self) -> Option<Pattern> {
        match *self {
            RunKind::Goto(_) => None,
            RunKind::Grid { pattern, .. } => Some(Pattern::Grid(pattern)),
            RunKind::Path { pattern, .. }
            | RunKind::Traced { pattern, .. }
            | RunKind::Marked { pattern, .. } => Some(pattern),
        }
    }

    /// Whether the run ends after one pass (a goto holds instead).
    pub(super) fn once(&self) -> bool {
        match *self {
            RunKind::Goto(_) => true,
            RunKind::Grid { once, .. }
            | RunKind::Path { once, .. }
            | RunKind::Traced { once, .. }
            | RunKind::Marked { once, .. } => once,
        }
    }

    /// The name in logs and notices.
    pub(super) fn name(&self) -> &'static str {
        self.pattern().map_or("goto", |p| p.name())
    }
}

/// An active pattern or goto.
#[derive(Debug, Clone, Copy)]
pub(super) struct Run {
    pub(super) kind: RunKind,
    /// Index of the current point within the pass.
    pub(super) index: usize,
    /// Completed passes.
    pub(super) pass: u32,
    pub(super) phase: Phase,
    /// Servo move in flight.
    pub(super) seq: u32,
    /// End of the dwell.
    pub(super) dwell_until: Option<Instant>,
    /// The gimbal has not finished the current point (move + dwell).
    pub(super) gimbal_busy: bool,
    /// The galvo has not reported the current point done.
    pub(super) galvo_busy: bool,
    /// Request number of the galvo point in flight.
    pub(super) galvo_seq: u32,
}

impl Run {
    fn new(kind: RunKind) -> Self {
        Self {
            kind,
            index: 0,
            pass: 0,
            phase: Phase::Moving,
            seq: 0,
            dwell_until: None,
            gimbal_busy: false,
            galvo_busy: false,
            galvo_seq: 0,
        }
    }
}

mod points;
