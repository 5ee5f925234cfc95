//! One scenario over a serial console: its script typed as the simulator's
//! host types it, the board's replies and `[trace …]` notices collected
//! into the board-neutral `scenario::Outcome`.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use laser_sim::script::Step;

use crate::qemu::{BoardStep, LogLine, parse_board_script, parse_line};
use crate::scenario::{Outcome, Scenario};
use crate::serial::Console;

/// How the runner resets the board for `@reset` (none: such scenarios are
/// skipped).
pub type Reset<'a> = Option<&'a dyn Fn() -> Result<()>>;

/// How long one reply may take, s (a `save` may erase a flash sector).
const REPLY_LIMIT: Duration = Duration::from_secs(30);
/// How long the sequencer may take to be idle after the script.
const IDLE_LIMIT: Duration = Duration::from_secs(60);

/// What running a scenario gave.
pub enum Ran {
    /// The board ran it.
    Outcome(Outcome),
    /// It needs a galvo and the board has none.
    NoGalvo,
    /// It switches the laser controls' inputs, which the console cannot.
    SwitchesInputs,
}

/// The console with what the board said so far.
struct Session<'a> {
    console: &'a mut Console,
    outcome: Outcome,
    /// Closing replies still owed to scenario lines.
    owed: usize,
    /// Added to the board's clock after a reset (it starts again at 0), µs.
    clock_offset_us: u64,
}

impl Session<'_> {
    /// Files one line from the board.
    fn take(&mut self, line: String, harness: &mut Option<(Vec<String>, Option<String>)>) {
        if let Some(inner) = line
            .strip_prefix("[trace ")
            .and_then(|l| l.strip_suffix(']'))
        {
            self.trace(inner);
            return;
        }
        if let Some((data, closer)) = harness.as_mut() {
            if line.starts_with('[') || line.starts_with("Grbl ") {
                self.outcome.notices.push(line);
            } else if line == "ok" || line.starts_with("error") {
                *closer = Some(line);
            } else {
                data.push(line);
            }
            return;
        }
        if line.starts_with('[') {
            self.outcome.notices.push(line.clone());
        } else if (line == "ok" || line.starts_with("error")) && self.owed > 0 {
            self.owed -= 1;
            if line.starts_with("error") {
                self.outcome.error_replies += 1;
            }
        }
        self.outcome.transcript.push(line);
    }

    /// One trace record (`<µs> @laser …` / `<µs> @event …`).
    fn trace(&mut self, record: &str) {
        let o = &mut self.outcome;
        match parse_line(record) {
            Some(LogLine::Laser(t, level)) => {
                let t = t + self.clock_offset_us;
                let lit = o.laser_events.last().is_some_and(|(_, on)| *on);
                if lit != (level > 0) {
                    o.laser_events.push((t, level > 0));
                }
                o.end_us = o.end_us.max(t);
            }
            Some(LogLine::Event(t, event)) => {
                let t = t + self.clock_offset_us;
                o.events.push((t, event));
                o.end_us = o.end_us.max(t);
            }
            _ => {}
        }
    }

    /// Reads and files lines until `done` or `limit` has passed; whether
    /// `done` was reached.
    fn pump(&mut self, limit: Duration, done: impl Fn(&Self) -> bool) -> Result<bool> {
        let deadline = Instant::now() + limit;
        let mut none = None;
        while !done(self) {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Ok(false);
            }
            if let Some(line) = self.console.read_line(left)? {
                self.take(line, &mut none);
            }
        }
        Ok(true)
    }

    /// A command of the runner's own (not part of the scenario's
    /// transcript): its data lines and closer.
    fn harness(&mut self, command: &str) -> Result<(Vec<String>, String)> {
        self.console.send_line(command)?;
        let deadline = Instant::now() + REPLY_LIMIT;
        let mut reply = Some((Vec::new(), None));
        loop {
            if let Some((data, Some(closer))) = reply.take_if(|(_, c)| c.is_some()) {
                return Ok((data, closer));
            }
            let left = deadline.saturating_duration_since(Instant::now());
            let Some(line) = self.console.read_line(left)? else {
                bail!("no reply to the runner's {command:?}");
            };
            self.take(line, &mut reply);
        }
    }

    /// Switches the trace on (after a boot too).
    fn trace_on(&mut self) -> Result<()> {
        let (_, closer) = self.harness("trace on")?;
        if closer != "ok" {
            bail!(
                "`trace on` answered {closer:?}: flash this checkout's firmware (`cargo xtask hil --flash`)"
            );
        }
        Ok(())
    }

    /// Polls `status` until the sequencer is idle.
    fn wait_idle(&mut self) -> Result<bool> {
        let deadline = Instant::now() + IDLE_LIMIT;
        while Instant::now() < deadline {
            let (data, _) = self.harness("status")?;
            if data.iter().any(|l| l == "state: idle") {
                return Ok(true);
            }
            self.pump(Duration::from_millis(200), |_| false)?;
        }
        Ok(false)
    }
}

/// `params` as (name, value) pairs.
fn params(session: &mut Session<'_>) -> Result<Vec<(String, String)>> {
    let (data, _) = session.harness("params")?;
    Ok(data
        .iter()
        .filter_map(|l| {
            let (name, rest) = l.split_once(" = ")?;
            let value = rest.split_whitespace().next()?;
            Some((name.to_owned(), value.to_owned()))
        })
        .collect())
}

/// Runs `scenario` on the board behind `console` (reopened at `port` after
/// a reset).
pub fn run_scenario(
    console: &mut Console,
    port: &Path,
    scenario: &Scenario,
    reset: Reset<'_>,
) -> Result<Ran> {
    console.drain(Duration::from_millis(300))?;
    let mut session = Session {
        console,
        outcome: Outcome {
            board: "serial console",
            boots: 1,
            ..Outcome::default()
        },
        owed: 0,
        clock_offset_us: 0,
    };
    // As after a boot: nothing running, the gimbal drawing, the exact
    // model (what is not a parameter; the parameters are put back after
    // each scenario).
    session.harness("stop")?;
    if scenario.galvo_dac {
        let (_, closer) = session.harness("target galvo")?;
        if closer.contains("no galvo output") {
            return Ok(Ran::NoGalvo);
        }
    }
    session.harness("target gimbal")?;
    session.harness("model exact")?;
    if scenario.laser_controls {
        return Ok(Ran::SwitchesInputs);
    }
    arm(&mut session)?;
    let before = params(&mut session)?;
    session.trace_on()?;
    let steps = parse_board_script(&scenario.script)?;
    for step in steps {
        match step {
            BoardStep::Script(Step::Send(line)) => {
                session.outcome.transcript.push(format!("> {line}"));
                session.console.send_line(&line)?;
                session.owed += 1;
                if !session.pump(REPLY_LIMIT, |s| s.owed == 0)? {
                    bail!("no reply to {line:?}");
                }
            }
            BoardStep::Script(Step::SendAhead(line)) => {
                session.outcome.transcript.push(format!("> {line}"));
                session.console.send_line(&line)?;
                session.owed += 1;
            }
            BoardStep::Script(Step::WaitMs(ms)) => {
                session.pump(Duration::from_millis(ms), |_| false)?;
            }
            BoardStep::Script(Step::StallReadMs(ms)) => {
                std::thread::sleep(Duration::from_millis(ms));
            }
            BoardStep::Script(Step::Realtime(byte)) => session.console.send_bytes(&[byte])?,
            BoardStep::Script(Step::StopButton) => {
                bail!("the stop button cannot be pressed over the console")
            }
            BoardStep::Script(Step::Interlock(_) | Step::Key(_)) => {
                bail!("the interlock and key cannot be switched over the console")
            }
            BoardStep::Script(Step::ServoCable { .. }) => {
                bail!("a servo cannot be unplugged over the console")
            }
            BoardStep::Script(Step::ClosePort | Step::OpenPort) => {
                bail!("@close/@open: the harness keeps its port open")
            }
            BoardStep::Reset => {
                session.pump(REPLY_LIMIT, |s| s.owed == 0)?;
                let Some(reset) = reset else {
                    bail!("the scenario resets the board and this run cannot");
                };
                session.clock_offset_us = session.outcome.end_us;
                reset()?;
                *session.console = Console::open(port)?;
                session.console.drain(Duration::from_millis(500))?;
                session.outcome.boots += 1;
                session.trace_on()?;
            }
        }
    }
    session.outcome.script_done = session.pump(REPLY_LIMIT, |s| s.owed == 0)?;
    session.outcome.idle_at_end = session.wait_idle()?;
    session.harness("trace off")?;
    // Put back what the scenario changed (and save it again if it saved).
    let after = params(&mut session)?;
    for ((name, was), (_, now)) in before.iter().zip(&after) {
        if was != now {
            session.harness(&format!("set {name} {was}"))?;
        }
    }
    if scenario.script.lines().any(|l| l.trim() == "save") {
        session.harness("save")?;
    }
    Ok(Ran::Outcome(session.outcome))
}

/// Arms the laser controls (a board with them starts not armed) and waits
/// out the emission indicator's delay; a board without them is fine.
fn arm(session: &mut Session<'_>) -> Result<()> {
    let (data, _) = session.harness("get laser.emission_delay_s")?;
    let delay_s = data
        .iter()
        .find_map(|l| l.strip_prefix("laser.emission_delay_s = "))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|value| value.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s >= 0.0)
        .unwrap_or(60.0);
    let (_, closer) = session.harness("arm")?;
    if closer == "ok" {
        session.pump(Duration::from_secs_f64(delay_s + 0.2), |_| false)?;
    } else if !closer.contains("no laser controls") {
        bail!(
            "`arm` refused ({closer}): close the interlock and key inputs \
             (PD1 and PD2 to GND, docs/laser-safety.md)"
        );
    }
    Ok(())
}
