//! Simulator scripts: one command line per line, `wait <ms>` pauses in
//! simulated time, blank lines and `#` comments are skipped. Lines starting
//! with `@` direct the simulated host instead of being typed:
//! `@stall-read <ms>` makes it stop reading the device's output for that
//! long (the script goes on, so lines can be typed during the stall),
//! `@type-ahead <line>` types a line without waiting for its reply,
//! `@realtime <byte>` sends one of grbl's realtime bytes (`?`, `!`, `~`
//! or hex: `0x18`, `0x9b`, …; no line, no reply awaited), `@button`
//! presses the board's stop button, `@close` / `@open` close the
//! console port (unplug: what was not read yet is lost) and open it
//! again (a new session), `@interlock open|closed` and `@key off|on`
//! set the laser controls' inputs (a script that uses them runs on a
//! board with the laser controls fitted), and `@unplug-servo <slot>` /
//! `@plug-servo <slot>` unplug and plug back the cable of a servo on the bus (slots
//! count from 1 in the order the bus was built: yaw, pitch, then any
//! more; a servo unplugged hears and answers nothing).

use anyhow::{Context, Result, bail};

/// One step of a script.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// Send this line to the command line and wait for its reply.
    Send(String),
    /// Let simulated time pass, ms.
    WaitMs(u64),
    /// The host stops reading the device's output for this long, ms, from
    /// now; the script goes on meanwhile.
    StallReadMs(u64),
    /// Send this line without waiting for its reply (the next `Send`, and
    /// the end of the script, wait for every reply outstanding).
    SendAhead(String),
    /// Press the board's stop button (stop, laser off, no reply).
    StopButton,
    /// Send one grbl realtime byte (no line end, no reply awaited).
    Realtime(u8),
    /// Unplug (or plug back) the cable of the servo in `slot` (0-based;
    /// the script counts from 1).
    ServoCable {
        /// Slot on the bus, from 0.
        slot: usize,
        /// Plugged in after the step.
        plugged: bool,
    },
    /// The host closes the port (DTR drops): replies not read yet are
    /// lost, as are lines still awaiting them.
    ClosePort,
    /// The host opens the port again (a new session).
    OpenPort,
    /// Close (`true`) or open the laser controls' remote interlock.
    Interlock(bool),
    /// Turn the laser controls' key switch on (`true`) or off.
    Key(bool),
}

impl Step {
    /// Whether the step needs the board's laser controls.
    pub fn uses_laser_controls(&self) -> bool {
        matches!(self, Step::Interlock(_) | Step::Key(_))
    }
}

/// The level of `@interlock open|closed` / `@key off|on`.
fn control_level(
    directive: &str,
    word: Option<&str>,
    [off, on]: [&str; 2],
    number: usize,
) -> Result<bool> {
    match word {
        Some(w) if w == on => Ok(true),
        Some(w) if w == off => Ok(false),
        _ => bail!("script line {number}: `{directive}` needs {off} or {on}"),
    }
}

/// The byte of `@realtime <byte>`: one of grbl's realtime commands, as
/// `?`, `!`, `~` or hex `0xNN`.
fn realtime_byte(word: Option<&str>, number: usize) -> Result<u8> {
    let byte = match word {
        Some("?") => b'?',
        Some("!") => b'!',
        Some("~") => b'~',
        Some(hex) if hex.starts_with("0x") => u8::from_str_radix(&hex[2..], 16)
            .with_context(|| format!("script line {number}: bad byte {hex:?}"))?,
        _ => bail!("script line {number}: `@realtime` needs ?, !, ~ or 0xNN"),
    };
    if laser_app::grbl::realtime::Realtime::from_byte(byte).is_none() {
        bail!("script line {number}: 0x{byte:02x} is not a realtime command");
    }
    Ok(byte)
}

/// A whole number of milliseconds: the only argument of `word`.
fn ms_argument<'a>(
    word: &str,
    mut args: impl Iterator<Item = &'a str>,
    number: usize,
) -> Result<u64> {
    let ms = args
        .next()
        .with_context(|| format!("script line {number}: `{word}` needs a time in ms"))?;
    let ms: u64 = ms
        .parse()
        .with_context(|| format!("script line {number}: bad {word} time {ms:?}"))?;
    if args.next().is_some() {
        bail!("script line {number}: `{word} <ms>` takes one argument");
    }
    Ok(ms)
}

/// Parses a script; `wait` needs a whole number of milliseconds.
pub fn parse_script(text: &str) -> Result<Vec<Step>> {
    let mut steps = Vec::new();
    for (number, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let number = number + 1;
        let mut words = line.split_ascii_whitespace();
        match words.next() {
            Some("wait") => steps.push(Step::WaitMs(ms_argument("wait", words, number)?)),
            Some("@stall-read") => {
                steps.push(Step::StallReadMs(ms_argument(
                    "@stall-read",
                    words,
                    number,
                )?));
            }
            Some("@type-ahead") => {
                let typed = line.trim_start_matches("@type-ahead").trim();
                if typed.is_empty() {
                    bail!("script line {number}: `@type-ahead` needs a line to type");
                }
                steps.push(Step::SendAhead(typed.to_owned()));
            }
            Some("@button") if line == "@button" => steps.push(Step::StopButton),
            Some("@close") if line == "@close" => steps.push(Step::ClosePort),
            Some("@open") if line == "@open" => steps.push(Step::OpenPort),
            Some("@realtime") => steps.push(Step::Realtime(realtime_byte(words.next(), number)?)),
            Some(d @ "@interlock") => steps.push(Step::Interlock(control_level(
                d,
                words.next(),
                ["open", "closed"],
                number,
            )?)),
            Some(d @ "@key") => steps.push(Step::Key(control_level(
                d,
                words.next(),
                ["off", "on"],
                number,
            )?)),
            Some(word @ ("@unplug-servo" | "@plug-servo")) => {
                let slot = ms_argument(word, words, number)
                    .ok()
                    .and_then(|n| usize::try_from(n).ok())
                    .filter(|&n| n >= 1)
                    .with_context(|| {
                        format!("script line {number}: `{word} <slot>` takes a slot from 1")
                    })?;
                steps.push(Step::ServoCable {
                    slot: slot - 1,
                    plugged: word == "@plug-servo",
                });
            }
            Some(directive) if directive.starts_with('@') => {
                bail!(
                    "script line {number}: unknown directive {directive:?} \
                     (@stall-read <ms>, @type-ahead <line>, @realtime <byte>, @button, @close, \
                     @open, @interlock open|closed, @key off|on, @unplug-servo <slot>, \
                     @plug-servo <slot>)"
                );
            }
            _ => steps.push(Step::Send(line.to_owned())),
        }
    }
    Ok(steps)
}

/// The script `cargo xtask sim` runs without arguments.
pub const DEMO_SCRIPT: &str = "\
# Demo: the galvo marks its tuning figure (square, circle, cross), then the
# gimbal visits the four corners once and the whole grid once (serpentine).
target galvo
pattern tuning 0 0 8 once
wait 1500
target gimbal
set dwell_ms 200
pattern corner once
wait 3000
pattern grid-full serpentine once
";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn realtime_bytes_parse_by_symbol_or_hex_and_others_are_refused() {
        let steps = parse_script("@realtime ?\n@realtime 0x9B\n@realtime 0x18\n").unwrap();
        assert_eq!(
            steps,
            vec![
                Step::Realtime(b'?'),
                Step::Realtime(0x9b),
                Step::Realtime(0x18)
            ]
        );
        assert!(parse_script("@realtime 0x41").is_err(), "A is not realtime");
        assert!(parse_script("@realtime").is_err());
        assert!(parse_script("@realtime 0xZZ").is_err());
    }

    #[test]
    fn laser_control_steps_parse_and_bad_levels_are_refused() {
        let steps =
            parse_script("@interlock open\n@interlock closed\n@key off\n@key on\n").unwrap();
        assert_eq!(
            steps,
            vec![
                Step::Interlock(false),
                Step::Interlock(true),
                Step::Key(false),
                Step::Key(true)
            ]
        );
        assert!(steps.iter().all(Step::uses_laser_controls));
        assert!(parse_script("@interlock on").is_err());
        assert!(parse_script("@key").is_err());
    }

    #[test]
    fn parses_commands_waits_and_skips_comments() {
        let steps = parse_script("# hi\n\npattern corner\n  wait 250 \nstop\n@button\n").unwrap();
        assert_eq!(
            steps,
            vec![
                Step::Send("pattern corner".into()),
                Step::WaitMs(250),
                Step::Send("stop".into()),
                Step::StopButton,
            ]
        );
    }

    #[test]
    fn bad_waits_name_the_line() {
        let err = parse_script("stop\nwait soon\n").unwrap_err().to_string();
        assert!(err.contains("line 2"), "{err}");
        assert!(parse_script("wait").is_err());
        assert!(parse_script("wait 1 2").is_err());
    }

    #[test]
    fn host_directives_parse_and_bad_ones_name_the_line() {
        let steps = parse_script("@stall-read 3000\n@type-ahead  get dwell_ms \nparams\n").unwrap();
        assert_eq!(
            steps,
            vec![
                Step::StallReadMs(3000),
                Step::SendAhead("get dwell_ms".into()),
                Step::Send("params".into())
            ]
        );
        for bad in [
            "@stall-read",
            "@stall-read 1 2",
            "@stall-read -5",
            "@type-ahead",
            "@stall 5",
        ] {
            let err = parse_script(&format!("stop\n{bad}\n"))
                .unwrap_err()
                .to_string();
            assert!(err.contains("line 2"), "{bad}: {err}");
        }
    }

    #[test]
    fn servo_cable_steps_count_slots_from_one() {
        let steps = parse_script("@unplug-servo 1\n@plug-servo 2\n").unwrap();
        assert_eq!(
            steps,
            vec![
                Step::ServoCable {
                    slot: 0,
                    plugged: false
                },
                Step::ServoCable {
                    slot: 1,
                    plugged: true
                }
            ]
        );
        for bad in [
            "@unplug-servo",
            "@unplug-servo 0",
            "@plug-servo x",
            "@plug-servo 1 2",
        ] {
            let err = parse_script(&format!("stop\n{bad}\n"))
                .unwrap_err()
                .to_string();
            assert!(err.contains("line 2"), "{bad}: {err}");
        }
    }

    #[test]
    fn demo_script_parses() {
        assert!(parse_script(DEMO_SCRIPT).unwrap().len() >= 3);
    }
}
