//! One run of the emulated board: started from an image, driven by a
//! script, stdin or a PTY, and what it gave.

use std::io::Write;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Receiver;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::Result;
use laser_sim::recorder::{Recording, SpotSample};

use super::board_log::BoardLog;
use super::machine::{Machine, MachineOptions};
use super::script::{BoardStep, parse_board_script, run_steps, wait_until_idle};
use super::terminal::{SharedTerminal, Terminal};

/// How a run on the board ended.
#[derive(Debug, Clone)]
pub struct BoardRun {
    /// The console transcript.
    pub terminal: Terminal,
    /// The log channel.
    pub log: BoardLog,
    /// Servo-bus frames and spot samples (host time).
    pub recording: Recording,
    /// The script was sent completely and every reply read.
    pub script_done: bool,
    /// The sequencer was idle at the end (only probed with `until_idle`).
    pub idle_at_end: bool,
    /// Host time at the end, µs.
    pub end_us: u64,
}

impl BoardRun {
    /// Whether `--until-idle` exits 0 (as the simulator's rule).
    pub fn succeeded(&self, allow_errors: bool) -> bool {
        self.script_done && self.idle_at_end && (allow_errors || self.terminal.error_replies == 0)
    }
}

/// Samples the spot (servo model, host time) and the reported laser every
/// `period` until `stop` is set.
fn spot_sampler(machine: &Machine, stop: Arc<AtomicBool>) -> JoinHandle<Vec<SpotSample>> {
    const PERIOD: Duration = Duration::from_millis(2);
    let (servos, log, t0) = (machine.servos.clone(), machine.log.clone(), machine.t0);
    std::thread::spawn(move || {
        let gimbal = laser_sim::physics::PhysicalGimbal::default();
        let mut samples = Vec::new();
        while !stop.load(Ordering::Relaxed) {
            let t_us = t0.elapsed().as_micros() as u64;
            let power = log.0.lock().map_or(0, |l| l.laser_level());
            let laser = power > 0;
            if let Ok(side) = servos.lock() {
                let yaw = side.bus.angle_deg(gimbal.yaw_id, t_us).unwrap_or(0.0);
                let pitch = side.bus.angle_deg(gimbal.pitch_id, t_us).unwrap_or(0.0);
                if let Some((x_cm, y_cm)) = gimbal.spot_cm(yaw, pitch) {
                    samples.push(SpotSample {
                        t_us,
                        x_cm,
                        y_cm,
                        laser,
                        power,
                    });
                }
            }
            std::thread::sleep(PERIOD);
        }
        samples
    })
}

/// What to do on a started board.
pub enum Drive {
    /// These steps.
    Steps(Vec<BoardStep>),
    /// Lines typed on stdin until it ends.
    Interactive,
    /// Bytes from the PTY bridge until `stop` is set.
    Pty {
        /// The host's bytes.
        from_host: Receiver<Vec<u8>>,
        /// Ends the run.
        stop: Arc<AtomicBool>,
    },
}

/// Runs `drive` on a fresh board from `elf`; `until_idle` then waits for
/// the sequencer to be idle; `trace` samples the spot.
pub fn run_board(
    elf: &Path,
    options: &MachineOptions,
    drive: Drive,
    until_idle: bool,
    max_time: Duration,
    trace: bool,
) -> Result<BoardRun> {
    let mut machine = Machine::start(elf, options)?;
    let deadline = Instant::now() + max_time;
    let stop = Arc::new(AtomicBool::new(false));
    let sampler = trace.then(|| spot_sampler(&machine, stop.clone()));
    let script_done = match drive {
        Drive::Steps(steps) => run_steps(&mut machine, &steps, deadline)?,
        Drive::Interactive => {
            for line in std::io::stdin().lines().map_while(Result::ok) {
                let steps = parse_board_script(&line).unwrap_or_default();
                run_steps(&mut machine, &steps, deadline)?;
            }
            true
        }
        Drive::Pty { from_host, stop } => {
            forward_typed(&machine, from_host)?;
            wait_for_stop(&stop, deadline);
            true
        }
    };
    let idle_at_end = script_done && until_idle && wait_until_idle(&mut machine, deadline)?;
    stop.store(true, Ordering::Relaxed);
    let spot = sampler.and_then(|s| s.join().ok()).unwrap_or_default();
    let end_us = machine.now_us();
    machine.stop();
    let terminal = machine
        .terminal
        .0
        .lock()
        .map(|t| t.clone())
        .unwrap_or_default();
    let log = machine.log.0.lock().map(|l| l.clone()).unwrap_or_default();
    let frames = machine
        .servos
        .lock()
        .map(|s| s.frames.clone())
        .unwrap_or_default();
    Ok(BoardRun {
        terminal,
        log,
        recording: Recording {
            frames,
            spot,
            ..Recording::default()
        },
        script_done,
        idle_at_end,
        end_us,
    })
}

/// Types the host's bytes on the board's console until the bridge or the
/// socket closes, recording each typed line in the transcript.
fn forward_typed(machine: &Machine, from_host: Receiver<Vec<u8>>) -> Result<()> {
    let mut console = machine.console_writer()?;
    let (terminal, t0) = (machine.terminal.clone(), machine.t0);
    std::thread::spawn(move || {
        let mut line = Vec::new();
        for bytes in from_host {
            record_typed(&terminal, t0, &mut line, &bytes);
            if console.write_all(&bytes).is_err() {
                return;
            }
        }
    });
    Ok(())
}

/// Adds `bytes` to the line being typed; a line end records it.
fn record_typed(terminal: &SharedTerminal, t0: Instant, line: &mut Vec<u8>, bytes: &[u8]) {
    for &b in bytes {
        if b != b'\r' && b != b'\n' {
            line.push(b);
            continue;
        }
        if !line.is_empty()
            && let Ok(mut term) = terminal.0.lock()
        {
            let t_us = t0.elapsed().as_micros() as u64;
            term.typed_line(t_us, &String::from_utf8_lossy(line));
        }
        line.clear();
    }
}

/// Waits until `stop` is set or `deadline` passes.
fn wait_for_stop(stop: &AtomicBool, deadline: Instant) {
    while !stop.load(Ordering::Relaxed) && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::{Condvar, Mutex};

    #[test]
    fn typed_bytes_in_chunks_are_recorded_as_lines_at_their_ends() {
        let terminal: SharedTerminal = Arc::new((Mutex::default(), Condvar::new()));
        let mut line = Vec::new();
        let t0 = Instant::now();
        record_typed(&terminal, t0, &mut line, b"vers");
        record_typed(&terminal, t0, &mut line, b"ion\r\n$I\r");
        record_typed(&terminal, t0, &mut line, b"\nG0 X1");
        let term = terminal.0.lock().unwrap();
        let typed: Vec<&str> = term.lines.iter().map(|(_, l)| l.as_str()).collect();
        assert_eq!(typed, ["> version", "> $I"]);
        assert_eq!(line, b"G0 X1");
    }
}
