//! grbl 1.1's numbered replies: `error:N` codes and `ALARM:N` codes, with
//! grbl's numbers wherever the meaning matches (grbl's
//! `doc/csv/error_codes_en_US.csv` and `alarm_codes_en_US.csv`).

/// Why a line was refused (`error:N`). The line changed nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GrblError {
    /// 1: a G-code word has no letter (e.g. `10` or `#1`).
    ExpectedCommandLetter,
    /// 2: a word's value is missing or not a number (`X`, `X-`, `X1e3`).
    BadNumberFormat,
    /// 3: a `$` command that is not recognized or supported.
    InvalidStatement,
    /// 4: a negative value where only positive ones make sense (F, N, P, S, T, `$N=`).
    NegativeValue,
    /// 5: `$H` without homing switches configured.
    HomingDisabled,
    /// 8: a `$` command that needs the machine idle.
    NotIdle,
    /// 9: G-code refused during an alarm or jog.
    GcodeLock,
    /// 11: the line was longer than the line buffer.
    LineOverflow,
    /// 15: a jog target outside the travel (the board extent).
    TravelExceeded,
    /// 16: a `$J=` line without `=`, with a prohibited word or without F.
    InvalidJogCommand,
    /// 20: an unsupported or unknown G/M command or word letter.
    UnsupportedCommand,
    /// 21: two commands of one modal group in a block.
    ModalGroupViolation,
    /// 22: a feed motion with no feed rate set (or G93 without F).
    UndefinedFeedRate,
    /// 23: a G/M command that needs an integer value has a fraction (`M3.5`).
    CommandValueNotInteger,
    /// 24: two commands that use axis words in one block (`G1 G92 X1`).
    AxisCommandConflict,
    /// 25: a value word repeated in a block (`X1 X2`).
    WordRepeated,
    /// 26: a command that needs axis words has none (`G92`, `G10 L20 P1`).
    NoAxisWords,
    /// 27: a line number outside 1..=9 999 999.
    InvalidLineNumber,
    /// 28: a command misses a value word it needs (`G4` without P).
    ValueWordMissing,
    /// 29: a work coordinate system other than G54 (`G10 P2`).
    UnsupportedCoordinateSystem,
    /// 30: G53 outside G0/G1.
    G53InvalidMotionMode,
    /// 31: axis words with no command using them (G80 active).
    AxisWordsExist,
    /// 32: an arc without an in-plane end word (X or Y).
    NoAxisWordsInPlane,
    /// 33: an invalid motion target: an arc whose end is not on its circle,
    /// an R arc ending where it starts, or a coordinate beyond ±1e9 mm.
    InvalidTarget,
    /// 34: an R arc whose radius is too small to reach its end.
    ArcRadiusError,
    /// 35: an I/J arc without an in-plane offset word.
    NoOffsetsInPlane,
    /// 36: value words no command uses (`G0 X1 P2`).
    UnusedWords,
    /// 38: a tool number above 255.
    MaxToolNumberExceeded,
}

impl GrblError {
    /// grbl's number, as sent in `error:N`.
    pub const fn code(self) -> u8 {
        use GrblError::*;
        match self {
            ExpectedCommandLetter => 1,
            BadNumberFormat => 2,
            InvalidStatement => 3,
            NegativeValue => 4,
            HomingDisabled => 5,
            NotIdle => 8,
            GcodeLock => 9,
            LineOverflow => 11,
            TravelExceeded => 15,
            InvalidJogCommand => 16,
            UnsupportedCommand => 20,
            ModalGroupViolation => 21,
            UndefinedFeedRate => 22,
            CommandValueNotInteger => 23,
            AxisCommandConflict => 24,
            WordRepeated => 25,
            NoAxisWords => 26,
            InvalidLineNumber => 27,
            ValueWordMissing => 28,
            UnsupportedCoordinateSystem => 29,
            G53InvalidMotionMode => 30,
            AxisWordsExist => 31,
            NoAxisWordsInPlane => 32,
            InvalidTarget => 33,
            ArcRadiusError => 34,
            NoOffsetsInPlane => 35,
            UnusedWords => 36,
            MaxToolNumberExceeded => 38,
        }
    }
}

/// Why the machine went into alarm (`ALARM:N`); motion and the laser stop
/// and only `$X` (or a reset) leaves it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Alarm {
    /// 2: a motion target outside the reachable workspace (soft limit).
    SoftLimit,
    /// 3: a soft reset (0x18) interrupted motion; the position may be lost.
    ResetWhileMoving,
    /// 6: homing stopped (a reset, a stop) before it ended.
    HomingReset,
    /// 8: homing could not pull off a switch (still closed after backing
    /// off).
    HomingPullOff,
    /// 9: homing found no switch within the travel.
    HomingNotFound,
}

impl Alarm {
    /// grbl's number, as sent in `ALARM:N`.
    pub const fn code(self) -> u8 {
        match self {
            Alarm::SoftLimit => 2,
            Alarm::ResetWhileMoving => 3,
            Alarm::HomingReset => 6,
            Alarm::HomingPullOff => 8,
            Alarm::HomingNotFound => 9,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_match_grbl_numbering() {
        // Spot checks against grbl's error_codes_en_US.csv / alarm_codes.
        assert_eq!(GrblError::ExpectedCommandLetter.code(), 1);
        assert_eq!(GrblError::BadNumberFormat.code(), 2);
        assert_eq!(GrblError::InvalidStatement.code(), 3);
        assert_eq!(GrblError::InvalidJogCommand.code(), 16);
        assert_eq!(GrblError::UnsupportedCommand.code(), 20);
        assert_eq!(GrblError::UndefinedFeedRate.code(), 22);
        assert_eq!(GrblError::WordRepeated.code(), 25);
        assert_eq!(GrblError::InvalidTarget.code(), 33);
        assert_eq!(GrblError::UnusedWords.code(), 36);
        assert_eq!(GrblError::MaxToolNumberExceeded.code(), 38);
        assert_eq!(Alarm::SoftLimit.code(), 2);
        assert_eq!(Alarm::ResetWhileMoving.code(), 3);
    }
}
