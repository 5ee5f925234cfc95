//! Scripts on the emulated board: the simulator's script format
//! (`laser-sim`'s `script` module parses each part), plus `@reset` lines,
//! which reset the board (the settings store keeps what was saved).

use std::time::{Duration, Instant};

use anyhow::Result;
use laser_sim::script::{Step, parse_script};

use super::machine::Machine;

/// The directive that resets the board between two parts of a script.
pub const RESET_DIRECTIVE: &str = "@reset";

/// One step of a script on the emulated board.
#[derive(Debug, Clone, PartialEq)]
pub enum BoardStep {
    /// A simulator script step.
    Script(Step),
    /// Reset the board and wait for it to boot.
    Reset,
}

/// Splits a script at its `@reset` lines into the parts between them.
pub fn split_at_resets(text: &str) -> Vec<String> {
    let mut parts = vec![String::new()];
    for line in text.lines() {
        if line.trim() == RESET_DIRECTIVE {
            parts.push(String::new());
        } else if let Some(part) = parts.last_mut() {
            part.push_str(line);
            part.push('\n');
        }
    }
    parts
}

/// Parses a script with `@reset` lines (errors name the line in its part).
pub fn parse_board_script(text: &str) -> Result<Vec<BoardStep>> {
    let mut steps = Vec::new();
    for (i, part) in split_at_resets(text).iter().enumerate() {
        if i > 0 {
            steps.push(BoardStep::Reset);
        }
        steps.extend(parse_script(part)?.into_iter().map(BoardStep::Script));
    }
    Ok(steps)
}

/// Runs one step; `false` when `deadline` passed first.
pub fn run_step(machine: &mut Machine, step: &BoardStep, deadline: Instant) -> Result<bool> {
    match step {
        BoardStep::Reset => {
            if !machine.replies_read(deadline) {
                return Ok(false);
            }
            machine.reset()?;
        }
        BoardStep::Script(Step::Send(line)) => {
            machine.type_line(line)?;
            return Ok(machine.replies_read(deadline));
        }
        BoardStep::Script(Step::SendAhead(line)) => machine.type_line(line)?,
        BoardStep::Script(Step::WaitMs(ms)) => {
            let until = Instant::now() + Duration::from_millis(*ms);
            if until > deadline {
                std::thread::sleep(deadline.saturating_duration_since(Instant::now()));
                return Ok(false);
            }
            std::thread::sleep(Duration::from_millis(*ms));
        }
        BoardStep::Script(Step::StallReadMs(ms)) => {
            if let Ok(mut term) = machine.terminal.0.lock() {
                let until = Instant::now() + Duration::from_millis(*ms);
                term.stall_until = Some(term.stall_until.map_or(until, |u| u.max(until)));
            }
        }
        BoardStep::Script(Step::StopButton) => machine.press_button()?,
        BoardStep::Script(Step::Realtime(byte)) => machine.send_realtime(*byte)?,
        BoardStep::Script(Step::Interlock(closed)) => machine.set_interlock(*closed)?,
        BoardStep::Script(Step::Key(on)) => machine.set_key(*on)?,
        BoardStep::Script(Step::ServoCable { slot, plugged }) => {
            let mut side = machine
                .servos
                .lock()
                .map_err(|_| anyhow::anyhow!("the servo bus thread panicked"))?;
            if !side.bus.set_plugged(*slot, *plugged) {
                anyhow::bail!("the servo bus has no slot {}", slot + 1);
            }
        }
        BoardStep::Script(Step::ClosePort | Step::OpenPort) => {
            anyhow::bail!("@close/@open: the QEMU board's console is a UART (no port to close)")
        }
    }
    Ok(true)
}

/// Runs `steps`, then waits for every reply; whether all of it happened
/// before `deadline`.
pub fn run_steps(machine: &mut Machine, steps: &[BoardStep], deadline: Instant) -> Result<bool> {
    for step in steps {
        if !run_step(machine, step, deadline)? {
            return Ok(false);
        }
    }
    Ok(machine.replies_read(deadline))
}

/// Whether a `status` reply says the sequencer is idle (or holding a
/// goto), as the simulator's `--until-idle` judges it.
pub fn status_says_idle(lines: &[String]) -> bool {
    let has = |l: &str| lines.iter().any(|x| x == l);
    has("state: idle") || (has("state: goto") && has("phase: holding"))
}

/// How often the idle probe asks.
const PROBE_PERIOD: Duration = Duration::from_millis(200);

/// Asks `status` (kept out of the transcript) until the sequencer is idle;
/// `false` at `deadline`.
pub fn wait_until_idle(machine: &mut Machine, deadline: Instant) -> Result<bool> {
    while Instant::now() < deadline {
        if let Ok(mut term) = machine.terminal.0.lock() {
            term.quiet = true;
            term.probe_lines.clear();
        }
        machine.type_line("status")?;
        let answered = machine.replies_read(deadline);
        let lines = match machine.terminal.0.lock() {
            Ok(mut term) => {
                term.quiet = false;
                std::mem::take(&mut term.probe_lines)
            }
            Err(_) => Vec::new(),
        };
        if answered && status_says_idle(&lines) {
            return Ok(true);
        }
        std::thread::sleep(PROBE_PERIOD);
    }
    Ok(false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resets_split_the_script_and_the_parts_parse_as_the_simulators() {
        let steps = parse_board_script("set dwell_ms 5\nsave\n @reset \nget dwell_ms\n").unwrap();
        assert_eq!(
            steps,
            vec![
                BoardStep::Script(Step::Send("set dwell_ms 5".into())),
                BoardStep::Script(Step::Send("save".into())),
                BoardStep::Reset,
                BoardStep::Script(Step::Send("get dwell_ms".into())),
            ]
        );
        assert!(parse_board_script("wait soon\n").is_err());
        assert!(parse_board_script("@reboot\n").is_err());
    }

    #[test]
    fn idle_is_idle_or_a_goto_holding() {
        let lines = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert!(status_says_idle(&lines(&["state: idle", "phase: -"])));
        assert!(status_says_idle(&lines(&["state: goto", "phase: holding"])));
        assert!(!status_says_idle(&lines(&["state: goto", "phase: moving"])));
        assert!(!status_says_idle(&lines(&[
            "state: pattern corner point 1 pass 0"
        ])));
    }
}
