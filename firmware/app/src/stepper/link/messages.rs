//! The messages between the sequencer and the stepper task: requests
//! ([`StepperRequest`], with the [`MoveShape`] of a move), refusals and
//! events.

use kinematics_core::Rotation;
use kinematics_core::frames::BoardPoint;

/// What the sequencer asks of the stepper task.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepperRequest {
    /// Go to a board point (cm) the way `shape` says: board lines and
    /// arcs from the previous target are cut into pieces (IK per piece
    /// end) that keep the spot within
    /// [`LINE_TOLERANCE_MM`](super::super::LINE_TOLERANCE_MM) of them.
    MoveTo {
        /// Request number.
        seq: u32,
        /// Board point, cm.
        point: BoardPoint,
        /// How to get there.
        shape: MoveShape,
        /// Spot speed along a line or arc on the board, mm/s (G-code's
        /// feed; `None`: the axes' speed limit, as for travel).
        feed_mm_s: Option<f64>,
    },
    /// Decelerate to rest at the acceleration limit along the path, drop
    /// the rest.
    Stop,
    /// Halt the steps at once (a G-code soft reset): the sequencer's
    /// shell calls [`StepperLink::halt`](super::StepperLink::halt) itself,
    /// so the step timer drops what is prepared at its next event.
    Halt,
    /// Home the axes with switches: seek, back off, latch, set the zero,
    /// pull off.
    Home,
    /// A G-code feed hold: as `Stop`, the moves since the last rest kept.
    Hold,
    /// After a hold came to rest: the kept moves again, from the rest
    /// point (the rest of the one it stopped in first).
    Resume,
    /// G-code's feed override, % (10–200): moves at a feed run at feed ×
    /// percent / 100 from now on, the one being cut too (within the
    /// acceleration limit). The sequencer's shell hands it over through
    /// [`StepperLink::set_feed_override`](super::StepperLink::set_feed_override)
    /// (the latest wins), not the request queue.
    FeedOverride {
        /// Percent of the programmed feed.
        percent: u8,
    },
    /// grbl's junction deviation for the moves from now on (G-code's
    /// `$11`; the product's runs use `stepper.junction_deg`), degrees of
    /// joint travel; takes effect when the planner is next empty.
    Junction {
        /// Junction deviation, degrees.
        deviation_deg: f64,
    },
}

/// How a move gets to its point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MoveShape {
    /// Straight in joint space (travel: the spot's board path is curved).
    Travel,
    /// Along the straight board line from the previous target.
    Line,
    /// Along the board arc about `centre` (cm) from the previous target;
    /// ending where it started is a full circle.
    Arc {
        /// Centre, cm.
        centre: BoardPoint,
        /// Direction.
        rotation: Rotation,
    },
}

impl MoveShape {
    /// `travel`, `line` or `arc` (for logs).
    pub fn name(&self) -> &'static str {
        match self {
            MoveShape::Travel => "travel",
            MoveShape::Line => "line",
            MoveShape::Arc { .. } => "arc",
        }
    }
}

/// Why a move was refused (nothing moved for it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StepperRefusal {
    /// A joint angle beyond the soft limits.
    SoftLimit,
    /// No joint angles reach the point (behind, off the board).
    Unreachable,
    /// The parameters are unusable (rates, acceleration, timing).
    BadConfig,
    /// A line is still being cut (one move at a time).
    Busy,
}

/// What the stepper task reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StepperEvent {
    /// Move `seq` has stepped its last step; the axes are at rest at
    /// `steps` (`[pan, tilt]`, microsteps).
    Arrived {
        /// Request number.
        seq: u32,
        /// Position, microsteps.
        steps: [i32; 2],
    },
    /// Move `seq` is being cut into the planner (a G-code sender's next
    /// move may follow; it is joined at speed).
    Taken {
        /// Request number.
        seq: u32,
    },
    /// Move `seq` was refused.
    Refused {
        /// Request number.
        seq: u32,
        /// Why.
        why: StepperRefusal,
    },
    /// A stop or halt came to rest at `steps`.
    Stopped {
        /// Position, microsteps.
        steps: [i32; 2],
    },
    /// A limit switch was pressed during a move: the steps halted at
    /// once at `steps`.
    LimitHit {
        /// Switches pressed: bit 0 pan, bit 1 tilt.
        axes: u8,
        /// Position, microsteps.
        steps: [i32; 2],
    },
    /// `Home` ended: zero set from the switches, at rest at `steps`.
    Homed {
        /// Position, microsteps.
        steps: [i32; 2],
    },
    /// `Home` failed (the position is not homed; the axes are at rest at
    /// `steps` of the zero they had, counted through the homing moves).
    HomingFailed {
        /// Why.
        why: HomingFailure,
        /// Position, microsteps.
        steps: [i32; 2],
    },
}

/// Why homing failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HomingFailure {
    /// No axis has a switch (`stepper.*.home_dir` 0).
    NoSwitches,
    /// The switch of axis 0 (pan) / 1 (tilt) never closed within the
    /// travel.
    NotFound(u8),
    /// The switch stayed closed after backing off.
    StillPressed(u8),
    /// A stop or the stop button ended it.
    Interrupted,
    /// The parameters do not allow the homing moves.
    BadConfig,
}
