//! The board as the online calibration drives it: its console commands
//! over the serial port, each checked for `ok`.

use std::path::Path;
use std::time::{Duration, Instant};

use crate::serial::Console;

/// How long one reply may take (a `save` may erase a flash sector).
const REPLY: Duration = Duration::from_secs(30);
/// How long the spot may take to arrive at a point.
const ARRIVAL: Duration = Duration::from_secs(15);
/// The error-model parameters, in `set` order.
pub const MODEL_PARAMS: [&str; 12] = [
    "err.dx.c0",
    "err.dx.c1",
    "err.dx.c2",
    "err.dx.c3",
    "err.dx.c4",
    "err.dx.c5",
    "err.dy.c0",
    "err.dy.c1",
    "err.dy.c2",
    "err.dy.c3",
    "err.dy.c4",
    "err.dy.c5",
];

/// The board's console.
pub struct Board {
    console: Console,
    /// The fitted model has been sent (and saved): it is not put back.
    pub model_sent: bool,
}

impl Board {
    /// Opens the console at `port`.
    pub fn open(port: &Path) -> Result<Self, String> {
        let mut console = Console::open(port).map_err(|e| format!("{e:#}"))?;
        console
            .drain(Duration::from_millis(300))
            .map_err(|e| format!("{e:#}"))?;
        Ok(Self {
            console,
            model_sent: false,
        })
    }

    /// Sends `line`: its data lines, or the board's error.
    fn command(&mut self, line: &str) -> Result<Vec<String>, String> {
        let (data, closer) = self
            .console
            .command(line, REPLY)
            .map_err(|e| format!("{e:#}"))?;
        if closer != "ok" {
            return Err(format!("the board answered `{line}` with `{closer}`"));
        }
        Ok(data)
    }

    /// Stops, aims with the gimbal and the exact model, arms the laser
    /// controls where fitted, lights the laser at targets, and zeroes the
    /// error model; the model it had (`set` lines).
    pub fn prepare(&mut self) -> Result<Vec<String>, String> {
        self.command("stop")?;
        self.command("target gimbal")?;
        self.command("model exact")?;
        self.arm()?;
        self.command("laser on")?;
        let mut saved = Vec::new();
        for name in MODEL_PARAMS {
            let data = self.command(&format!("get {name}"))?;
            let value = data
                .iter()
                .find_map(|l| l.strip_prefix(&format!("{name} = ")))
                .and_then(|rest| rest.split_whitespace().next())
                .ok_or_else(|| format!("`get {name}` gave no value: {data:?}"))?;
            saved.push(format!("set {name} {value}"));
        }
        let zero: Vec<String> = MODEL_PARAMS.iter().map(|n| format!("set {n} 0")).collect();
        self.set_model(&zero)?;
        Ok(saved)
    }

    /// Arms the laser controls and waits out the emission delay (a board
    /// without them answers that it has none).
    fn arm(&mut self) -> Result<(), String> {
        let (_, closer) = self
            .console
            .command("arm", REPLY)
            .map_err(|e| format!("{e:#}"))?;
        if closer == "ok" {
            let data = self.command("get laser.emission_delay_s")?;
            let delay_s = data
                .iter()
                .find_map(|l| l.strip_prefix("laser.emission_delay_s = "))
                .and_then(|rest| rest.split_whitespace().next())
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|s| s.is_finite() && (0.0..=60.0).contains(s))
                .unwrap_or(60.0);
            std::thread::sleep(Duration::from_secs_f64(delay_s + 0.2));
        } else if !closer.contains("no laser controls") {
            return Err(format!(
                "`arm` refused ({closer}): close the interlock and turn the key (docs/laser-safety.md)"
            ));
        }
        Ok(())
    }

    /// Sends the `set` lines of `lines` (other lines are comments).
    pub fn set_model(&mut self, lines: &[String]) -> Result<(), String> {
        for line in lines.iter().filter(|l| l.starts_with("set ")) {
            self.command(line)?;
        }
        Ok(())
    }

    /// Sends the fitted model (`calib fit --output` text) and `save`s it.
    pub fn send_model(&mut self, text: &str) -> Result<(), String> {
        let lines: Vec<String> = text.lines().map(str::to_owned).collect();
        self.model_sent = true;
        self.set_model(&lines)?;
        self.command("save")?;
        Ok(())
    }

    /// `goto` the board point `p_mm` and waits until the spot holds there
    /// with the laser on.
    pub fn aim(&mut self, p_mm: [f64; 2]) -> Result<(), String> {
        self.command(&format!("goto {:.4} {:.4}", p_mm[0] / 10.0, p_mm[1] / 10.0))?;
        let deadline = Instant::now() + ARRIVAL;
        loop {
            let status = self.command("status")?;
            let holding = status
                .iter()
                .any(|l| l == "phase: holding" || l == "phase: dwelling");
            let lit = status.iter().any(|l| l.starts_with("laser: on"));
            if holding && lit {
                return Ok(());
            }
            if let Some(fault) = status
                .iter()
                .find(|l| l.starts_with("faults:") && *l != "faults: none")
            {
                return Err(format!("the board reports {fault}"));
            }
            if Instant::now() > deadline {
                return Err(format!(
                    "the spot did not arrive lit within {} s: {status:?}",
                    ARRIVAL.as_secs()
                ));
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Stops (laser off).
    pub fn dark(&mut self) -> Result<(), String> {
        self.command("stop").map(|_| ())
    }
}
