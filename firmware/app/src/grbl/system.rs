//! grbl's `$` system commands (grbl's `doc/markdown/commands.md`).

use super::error::GrblError;
use super::words::Words;

/// What `$RST=` restores.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RestoreScope {
    /// `$RST=$`: settings to defaults.
    Settings,
    /// `$RST=#`: G54/G92 offsets to zero.
    Offsets,
    /// `$RST=*`: both.
    All,
}

/// A `$` command.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SystemCommand<'a> {
    /// `$`: `[HLP:…]`.
    Help,
    /// `$$`: every setting as `$N=value`.
    Settings,
    /// `$#`: offsets (`[G54:…]`, `[G92:…]`, …).
    Parameters,
    /// `$G`: parser state `[GC:…]`.
    ParserState,
    /// `$I`: `[VER:…]` and `[OPT:…]`.
    BuildInfo,
    /// `$N`: startup lines (none are stored; answered with empty `$N0=`/`$N1=`).
    StartupLines,
    /// `$C`: toggle check mode (parse, do not move).
    CheckMode,
    /// `$X`: leave the alarm state.
    Unlock,
    /// `$H`: homing, here: aim at the board origin.
    Home,
    /// `$SLP`: sleep.
    Sleep,
    /// `$J=<gcode>`: jog; the G-code text after `=`.
    Jog(&'a str),
    /// `$RST=$|#|*`.
    Restore(RestoreScope),
    /// `$N=value`: set grbl setting N (checked against [`super::settings_map`]).
    SetSetting {
        /// grbl setting number.
        number: u16,
        /// Value, ≥ 0.
        value: f64,
    },
}

/// Parses a line that starts with `$` (leading blanks allowed).
pub fn parse_system(line: &str) -> Result<SystemCommand<'_>, GrblError> {
    let text = line.trim_matches([' ', '\t']);
    let body = text.strip_prefix('$').ok_or(GrblError::InvalidStatement)?;
    if let Some(jog) = body.strip_prefix("J=") {
        return Ok(SystemCommand::Jog(jog));
    }
    if body.starts_with('J') {
        return Err(GrblError::InvalidJogCommand);
    }
    // grbl ignores spaces in the rest of a `$` line.
    let mut compact = heapless::String::<24>::new();
    for c in body.chars().filter(|c| !matches!(c, ' ' | '\t')) {
        compact
            .push(c.to_ascii_uppercase())
            .map_err(|_| GrblError::InvalidStatement)?;
    }
    let command = match compact.as_str() {
        "" => SystemCommand::Help,
        "$" => SystemCommand::Settings,
        "#" => SystemCommand::Parameters,
        "G" => SystemCommand::ParserState,
        "I" => SystemCommand::BuildInfo,
        "N" => SystemCommand::StartupLines,
        "C" => SystemCommand::CheckMode,
        "X" => SystemCommand::Unlock,
        "H" => SystemCommand::Home,
        "SLP" => SystemCommand::Sleep,
        "RST=$" => SystemCommand::Restore(RestoreScope::Settings),
        "RST=#" => SystemCommand::Restore(RestoreScope::Offsets),
        "RST=*" => SystemCommand::Restore(RestoreScope::All),
        other => return parse_setting(other),
    };
    Ok(command)
}

/// `N=value`.
fn parse_setting(text: &str) -> Result<SystemCommand<'static>, GrblError> {
    let (number, value) = text.split_once('=').ok_or(GrblError::InvalidStatement)?;
    if number.is_empty() || number.len() > 3 || !number.bytes().all(|b| b.is_ascii_digit()) {
        return Err(GrblError::InvalidStatement);
    }
    let number: u16 = number.parse().map_err(|_| GrblError::InvalidStatement)?;
    let value = read_value(value)?;
    if value < 0.0 {
        return Err(GrblError::NegativeValue);
    }
    if super::settings_map::find(number).is_none() {
        return Err(GrblError::InvalidStatement);
    }
    Ok(SystemCommand::SetSetting { number, value })
}

/// A bare number (`[+|-]digits[.digits]`), nothing else, read with the
/// same rules as a G-code word's value.
fn read_value(text: &str) -> Result<f64, GrblError> {
    let mut line = heapless::String::<32>::new();
    line.push('X').map_err(|_| GrblError::BadNumberFormat)?;
    line.push_str(text)
        .map_err(|_| GrblError::BadNumberFormat)?;
    let mut words = Words::new(&line);
    match (words.next(), words.next()) {
        (Some(Ok(word)), None) => Ok(word.value),
        (Some(Err(e)), _) => Err(e),
        _ => Err(GrblError::BadNumberFormat),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn system_commands_parse() {
        assert_eq!(parse_system("$"), Ok(SystemCommand::Help));
        assert_eq!(parse_system("$$"), Ok(SystemCommand::Settings));
        assert_eq!(parse_system("$#"), Ok(SystemCommand::Parameters));
        assert_eq!(parse_system("$g"), Ok(SystemCommand::ParserState));
        assert_eq!(parse_system("$I"), Ok(SystemCommand::BuildInfo));
        assert_eq!(parse_system("$N"), Ok(SystemCommand::StartupLines));
        assert_eq!(parse_system("$C"), Ok(SystemCommand::CheckMode));
        assert_eq!(parse_system(" $X "), Ok(SystemCommand::Unlock));
        assert_eq!(parse_system("$H"), Ok(SystemCommand::Home));
        assert_eq!(parse_system("$SLP"), Ok(SystemCommand::Sleep));
        assert_eq!(
            parse_system("$J=G91 X1 F100"),
            Ok(SystemCommand::Jog("G91 X1 F100"))
        );
        assert_eq!(
            parse_system("$RST=*"),
            Ok(SystemCommand::Restore(RestoreScope::All))
        );
        assert_eq!(
            parse_system("$110=5000.5"),
            Ok(SystemCommand::SetSetting {
                number: 110,
                value: 5000.5
            })
        );
        assert_eq!(
            parse_system("$32 = 1"),
            Ok(SystemCommand::SetSetting {
                number: 32,
                value: 1.0
            })
        );
    }

    #[test]
    fn bad_system_commands_get_grbl_errors() {
        assert_eq!(parse_system("$Q"), Err(GrblError::InvalidStatement));
        assert_eq!(parse_system("$RST=x"), Err(GrblError::InvalidStatement));
        assert_eq!(parse_system("$J G91 X1"), Err(GrblError::InvalidJogCommand));
        assert_eq!(parse_system("$999=1"), Err(GrblError::InvalidStatement));
        assert_eq!(parse_system("$1000=1"), Err(GrblError::InvalidStatement));
        assert_eq!(parse_system("$110=abc"), Err(GrblError::BadNumberFormat));
        assert_eq!(parse_system("$110="), Err(GrblError::BadNumberFormat));
        assert_eq!(parse_system("$110=1.2.3"), Err(GrblError::BadNumberFormat));
        assert_eq!(parse_system("$110=-5"), Err(GrblError::NegativeValue));
        assert_eq!(
            parse_system("$1=2 X"),
            Err(GrblError::BadNumberFormat),
            "trailing junk"
        );
    }
}
