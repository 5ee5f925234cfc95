//! The G-code parser's modal state (what `$G` reports) and work offsets.

use super::block::{Laser, PointMm, SpindleMode};

/// Motion mode, modal group 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MotionMode {
    /// G0.
    #[default]
    Rapid,
    /// G1.
    Linear,
    /// G2.
    ArcClockwise,
    /// G3.
    ArcCounterClockwise,
    /// G80: motion cancelled (axis words are an error).
    Cancel,
}

/// Units of lengths and feeds in G-code words (G20/G21).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Units {
    /// G21.
    #[default]
    Millimetres,
    /// G20: 25.4 mm.
    Inches,
}

impl Units {
    /// mm per unit.
    pub const fn mm_per_unit(self) -> f64 {
        match self {
            Units::Millimetres => 1.0,
            Units::Inches => 25.4,
        }
    }
}

/// G90/G91.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Distance {
    /// G90.
    #[default]
    Absolute,
    /// G91.
    Incremental,
}

/// G93/G94.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FeedMode {
    /// G94: F is units/min.
    #[default]
    UnitsPerMinute,
    /// G93: F is 1/min (the move takes 1/F minutes); F in every feed block.
    InverseTime,
}

/// M7/M8/M9 (accepted and reported; this controller has no coolant output).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Coolant {
    /// M7.
    pub mist: bool,
    /// M8 (air assist on laser machines).
    pub flood: bool,
}

/// The parser state: modal groups, F, S, T, position and offsets.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParserState {
    /// Group 1.
    pub motion: MotionMode,
    /// Group 6.
    pub units: Units,
    /// Group 3.
    pub distance: Distance,
    /// Group 5.
    pub feed_mode: FeedMode,
    /// M3/M4/M5.
    pub spindle: SpindleMode,
    /// M7/M8/M9.
    pub coolant: Coolant,
    /// Modal feed, mm/min (0 = undefined).
    pub feed_mm_min: f64,
    /// Modal laser power S.
    pub power: f64,
    /// Tool number (accepted, ignored).
    pub tool: u8,
    /// Last line number seen (N), 0 if none.
    pub line_number: u32,
    /// Where the programmed path ends after the last accepted line, board
    /// mm (machine coordinates).
    pub position: PointMm,
    /// G54 work coordinate origin, board mm (set by G10 L2/L20 P0/P1).
    pub g54: PointMm,
    /// G92 offset, mm.
    pub g92: PointMm,
}

impl ParserState {
    /// The state after power-up: G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0.
    pub const fn new() -> ParserState {
        ParserState {
            motion: MotionMode::Rapid,
            units: Units::Millimetres,
            distance: Distance::Absolute,
            feed_mode: FeedMode::UnitsPerMinute,
            spindle: SpindleMode::Off,
            coolant: Coolant {
                mist: false,
                flood: false,
            },
            feed_mm_min: 0.0,
            power: 0.0,
            tool: 0,
            line_number: 0,
            position: PointMm::ZERO,
            g54: PointMm::ZERO,
            g92: PointMm::ZERO,
        }
    }

    /// Work coordinate offset (grbl's `WCO`): machine = work + WCO, mm.
    pub fn work_offset(&self) -> PointMm {
        PointMm {
            x_mm: self.g54.x_mm + self.g92.x_mm,
            y_mm: self.g54.y_mm + self.g92.y_mm,
        }
    }

    /// The laser setting in effect.
    pub fn laser(&self) -> Laser {
        Laser {
            mode: self.spindle,
            power: self.power,
        }
    }

    /// After a soft reset: modal state as at power-up, but the position
    /// (where the machine is), G54 and G92 kept, as grbl keeps them.
    pub fn soft_reset(&mut self) {
        *self = ParserState {
            position: self.position,
            g54: self.g54,
            g92: self.g92,
            ..ParserState::new()
        };
    }

    /// M2/M30 (grbl 1.1): G1 G17 G90 G94 G54 M5 M9; F, S, offsets kept.
    pub fn end_program(&mut self) {
        self.motion = MotionMode::Linear;
        self.distance = Distance::Absolute;
        self.feed_mode = FeedMode::UnitsPerMinute;
        self.spindle = SpindleMode::Off;
        self.coolant = Coolant::default();
    }
}
