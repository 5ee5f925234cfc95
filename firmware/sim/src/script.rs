//! Simulator scripts: one command line per line, `wait <ms>` pauses in
//! simulated time, `@button` presses the board's stop button, blank lines
//! and `#` comments are skipped.

use anyhow::{Context, Result, bail};

/// One step of a script.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// Send this line to the command line and wait for its reply.
    Send(String),
    /// Let simulated time pass, ms.
    WaitMs(u64),
    /// Press the board's stop button (stop, laser off, no reply).
    StopButton,
}

/// Parses a script; `wait` needs a whole number of milliseconds.
pub fn parse_script(text: &str) -> Result<Vec<Step>> {
    let mut steps = Vec::new();
    for (number, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut words = line.split_ascii_whitespace();
        if words.next() == Some("wait") {
            let ms = words.next().with_context(|| {
                format!("script line {}: `wait` needs a time in ms", number + 1)
            })?;
            let ms: u64 = ms
                .parse()
                .with_context(|| format!("script line {}: bad wait time {ms:?}", number + 1))?;
            if words.next().is_some() {
                bail!("script line {}: `wait <ms>` takes one argument", number + 1);
            }
            steps.push(Step::WaitMs(ms));
        } else if line == "@button" {
            steps.push(Step::StopButton);
        } else {
            steps.push(Step::Send(line.to_owned()));
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
    fn demo_script_parses() {
        assert!(parse_script(DEMO_SCRIPT).unwrap().len() >= 3);
    }
}
