//! First pass over a line: words sorted into modal groups and value words,
//! with grbl's per-word checks (errors 1, 2, 4, 20, 21, 23, 25, 27, 38).
//! Nothing here depends on the parser state.

use super::block::SpindleMode;
use super::error::GrblError;
use super::state::{Distance, FeedMode, MotionMode, Units};
use super::words::Words;

/// Non-modal commands (modal group 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NonModal {
    /// G4 P…: dwell.
    Dwell,
    /// G10 L2/L20 P…: set the work coordinate origin.
    SetCoordinateData,
    /// G53: this block's motion in machine coordinates.
    MachineCoordinates,
    /// G92: set the G92 offset so the position reads as the given values.
    SetOffset,
    /// G92.1: clear the G92 offset.
    ClearOffset,
}

/// Program flow (M group 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgramFlow {
    /// M0.
    Pause,
    /// M1 (optional stop: ignored, as grbl does).
    OptionalStop,
    /// M2/M30.
    End,
}

/// Coolant words (M group 8).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoolantWord {
    /// M7.
    Mist,
    /// M8.
    Flood,
    /// M9.
    Off,
}

/// Value-word letters grbl knows, as bits.
pub const F: u16 = 1 << 0;
pub const I: u16 = 1 << 1;
pub const J: u16 = 1 << 2;
pub const K: u16 = 1 << 3;
pub const L: u16 = 1 << 4;
pub const N: u16 = 1 << 5;
pub const P: u16 = 1 << 6;
pub const R: u16 = 1 << 7;
pub const S: u16 = 1 << 8;
pub const T: u16 = 1 << 9;
pub const X: u16 = 1 << 10;
pub const Y: u16 = 1 << 11;
pub const Z: u16 = 1 << 12;
/// Axis words.
pub const AXES: u16 = X | Y | Z;
const LETTERS: &[u8; 13] = b"FIJKLNPRSTXYZ";

/// The words of one line, by role.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Collected {
    pub motion: Option<MotionMode>,
    pub non_modal: Option<NonModal>,
    pub distance: Option<Distance>,
    pub feed_mode: Option<FeedMode>,
    pub units: Option<Units>,
    pub program: Option<ProgramFlow>,
    pub spindle: Option<SpindleMode>,
    pub coolant: Option<CoolantWord>,
    /// Which value words are present (bits above).
    pub present: u16,
    values: [f64; 13],
    groups: u32,
}

impl Collected {
    /// The value of `letter_bit`, if present.
    pub fn value(&self, letter_bit: u16) -> Option<f64> {
        (self.present & letter_bit != 0).then(|| self.values[letter_bit.trailing_zeros() as usize])
    }

    /// Whether every G/M command of the line is in one of the G modal
    /// groups of `mask` (bit n = grbl's group n).
    pub fn only_groups(&self, mask: u32) -> bool {
        self.groups & !mask == 0
    }

    fn claim_group(&mut self, group: u32) -> Result<(), GrblError> {
        if self.groups & (1 << group) != 0 {
            return Err(GrblError::ModalGroupViolation);
        }
        self.groups |= 1 << group;
        Ok(())
    }

    fn g_word(&mut self, number: u16, fraction: u8) -> Result<(), GrblError> {
        use GrblError::{CommandValueNotInteger, UnsupportedCommand, UnsupportedCoordinateSystem};
        // Group numbers follow grbl's modal groups (G0, G1, …, G13).
        let (group, fraction_ok) = match (number, fraction) {
            (0..=3 | 80, _) => (1, false),
            (4 | 10 | 53, _) | (92, 0 | 10) => (0, number == 92),
            (17, _) => (2, false),
            (90 | 91, 0) => (3, false),
            (91, 10) => (4, true), // G91.1: arc offsets incremental (the only mode)
            (93 | 94, _) => (5, false),
            (20 | 21, _) => (6, false),
            (40, _) => (7, false),
            (49, _) => (8, false),
            (54, _) => (12, false),
            (55..=59, _) => return Err(UnsupportedCoordinateSystem),
            (61, _) => (13, false),
            _ => return Err(UnsupportedCommand),
        };
        if fraction != 0 && !fraction_ok {
            return Err(CommandValueNotInteger);
        }
        self.claim_group(group)?;
        match number {
            0 => self.motion = Some(MotionMode::Rapid),
            1 => self.motion = Some(MotionMode::Linear),
            2 => self.motion = Some(MotionMode::ArcClockwise),
            3 => self.motion = Some(MotionMode::ArcCounterClockwise),
            80 => self.motion = Some(MotionMode::Cancel),
            4 => self.non_modal = Some(NonModal::Dwell),
            10 => self.non_modal = Some(NonModal::SetCoordinateData),
            53 => self.non_modal = Some(NonModal::MachineCoordinates),
            92 if fraction == 0 => self.non_modal = Some(NonModal::SetOffset),
            92 => self.non_modal = Some(NonModal::ClearOffset),
            90 if fraction == 0 => self.distance = Some(Distance::Absolute),
            91 if fraction == 0 => self.distance = Some(Distance::Incremental),
            93 => self.feed_mode = Some(FeedMode::InverseTime),
            94 => self.feed_mode = Some(FeedMode::UnitsPerMinute),
            20 => self.units = Some(Units::Inches),
            21 => self.units = Some(Units::Millimetres),
            _ => {} // G17, G40, G49, G54, G61, G91.1: the only mode there is
        }
        Ok(())
    }

    fn m_word(&mut self, number: u16, fraction: u8) -> Result<(), GrblError> {
        if fraction != 0 {
            return Err(GrblError::CommandValueNotInteger);
        }
        let group = match number {
            0 | 1 | 2 | 30 => 4,
            3..=5 => 7,
            7..=9 => 8,
            _ => return Err(GrblError::UnsupportedCommand),
        };
        // M groups are numbered after the G groups.
        self.claim_group(16 + group)?;
        match number {
            0 => self.program = Some(ProgramFlow::Pause),
            1 => self.program = Some(ProgramFlow::OptionalStop),
            3 => self.spindle = Some(SpindleMode::Constant),
            4 => self.spindle = Some(SpindleMode::Dynamic),
            5 => self.spindle = Some(SpindleMode::Off),
            7 => self.coolant = Some(CoolantWord::Mist),
            8 => self.coolant = Some(CoolantWord::Flood),
            9 => self.coolant = Some(CoolantWord::Off),
            _ => self.program = Some(ProgramFlow::End),
        }
        Ok(())
    }

    fn value_word(&mut self, letter: u8, value: f64) -> Result<(), GrblError> {
        let index = LETTERS
            .iter()
            .position(|&l| l == letter)
            .ok_or(GrblError::UnsupportedCommand)?;
        let bit = 1u16 << index;
        if self.present & bit != 0 {
            return Err(GrblError::WordRepeated);
        }
        if bit & (F | N | P | S | T) != 0 && value < 0.0 {
            return Err(GrblError::NegativeValue);
        }
        if bit == N && value > 9_999_999.0 {
            return Err(GrblError::InvalidLineNumber);
        }
        if bit == T && value > 255.0 {
            return Err(GrblError::MaxToolNumberExceeded);
        }
        self.present |= bit;
        self.values[index] = value;
        Ok(())
    }
}

/// Sorts the words of `line`; the first offending word decides the error.
pub fn collect(line: &str) -> Result<Collected, GrblError> {
    let mut block = Collected::default();
    for word in Words::new(line) {
        let word = word?;
        match word.letter {
            b'G' | b'M' => {
                // grbl: integer part and two decimals of fraction (G91.1 → 91, 10).
                if !(0.0..1000.0).contains(&word.value) {
                    return Err(GrblError::UnsupportedCommand);
                }
                let whole = libm::trunc(word.value);
                let fraction = libm::round((word.value - whole) * 100.0) as u8;
                if word.letter == b'G' {
                    block.g_word(whole as u16, fraction)?;
                } else {
                    block.m_word(whole as u16, fraction)?;
                }
            }
            letter => block.value_word(letter, word.value)?,
        }
    }
    Ok(block)
}
