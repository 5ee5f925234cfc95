//! Why a parameter value was refused.

use core::fmt;

use crate::text::Interval;

/// Why `set` refused a value (nothing changed). Its text is the reason the
/// command line prints after `error: `.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SettingsError {
    /// The value is outside the parameter's range (or not finite).
    OutOfRange {
        /// The parameter's name.
        what: &'static str,
        /// Lowest accepted value, in the parameter's unit.
        min: f64,
        /// Highest accepted value, in the parameter's unit.
        max: f64,
    },
    /// The value is in range but not allowed (not a whole number, not a
    /// valid code, or against a rule between parameters); says why.
    Rejected(&'static str),
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SettingsError::OutOfRange { what, min, max } => {
                write!(f, "{what} out of range {}", Interval(*min, *max))
            }
            SettingsError::Rejected(why) => f.write_str(why),
        }
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for SettingsError {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "{}", defmt::Display2Format(self))
    }
}
