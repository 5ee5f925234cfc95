//! `cargo xtask qemu`: the firmware's task graph (`firmware/qemu-m4`, wired
//! by the same `laser_app::app::wire` as the STM32 image) on QEMU's
//! `mps2-an386` Cortex-M4F, with the simulator's servos on the servo UART
//! and the simulator's script format and options on the console.
//!
//! QEMU runs with `-icount shift=0`: 1 ns of virtual time per guest
//! instruction while the CPU runs; while it sleeps (WFI) virtual time
//! follows the host clock, so the board, the servos (host clock) and the
//! script's waits stay together in real time.

mod board_log;
mod defmt_log;
mod machine;
mod measure;
mod pelco;
mod pty;
mod script;
mod servo_bus;
mod terminal;

use std::io::{IsTerminal, Read};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Receiver;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use laser_sim::recorder::{Recording, SpotSample};

pub use board_log::{BoardEvent, BoardLog, LogLine, parse_line};
pub use defmt_log::check_channel as check_defmt_channel;
pub use machine::{Machine, MachineOptions};
pub use pelco::check_port as check_pelco_port;
pub use pty::{check_console as check_pty_console, with_board_on_pty};
pub use script::{BoardStep, parse_board_script, split_at_resets};
use script::{run_steps, wait_until_idle};
pub use terminal::Terminal;

use crate::toolchain::{TARGET, ensure_flip_link, target_dir};

/// The board's manifest, relative to the workspace root (a workspace of its
/// own, like the bench's).
pub const MANIFEST: &str = "firmware/qemu-m4/Cargo.toml";

/// Options of `cargo xtask qemu` (those of `cargo xtask sim` that apply).
#[derive(clap::Args, Debug)]
pub struct QemuArgs {
    /// Script of command lines, in the simulator's format (`wait <ms>`,
    /// `#` comments, `@stall-read <ms>`, `@type-ahead <line>`, `@button`),
    /// plus `@reset` (reset the board; saved settings survive); `-` reads
    /// it from stdin. Without it, piped stdin is the script.
    #[arg(long)]
    script: Option<PathBuf>,
    /// Type commands on stdin as the board runs, like a serial terminal
    /// (end with Ctrl-D).
    #[arg(long, conflicts_with = "script")]
    interactive: bool,
    /// Run until the script has ended and the sequencer is idle; exit 1 if
    /// any command got `error:` (unless --allow-errors).
    #[arg(long)]
    until_idle: bool,
    /// With --until-idle: `error:` replies do not fail the run.
    #[arg(long)]
    allow_errors: bool,
    /// Inject a fault, as `cargo xtask sim --fault` (times in ms since QEMU
    /// started): `servo-silent:<id>@<t_ms>[-<end_ms>]`, `servo-corrupt:<p>`,
    /// `servo-forge:<p>`, `servo-slow:<factor>`.
    #[arg(long = "fault")]
    faults: Vec<String>,
    /// Write every servo-bus frame: `t_ms tx|rx hex-bytes` (host ms).
    #[arg(long)]
    frames: Option<PathBuf>,
    /// Write the spot trace as CSV `t_ms,x_cm,y_cm,laser` (host ms; the
    /// spot from the simulated servos, the laser as the board reports it).
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Stop after this long, s (default 600; no limit with --interactive).
    #[arg(long)]
    max_time_s: Option<f64>,
    /// The console on a raw pseudo-terminal for a serial program or a
    /// G-code sender (its path is printed; with PATH also a symlink to it),
    /// until Ctrl-C or --max-time-s.
    #[arg(long, num_args = 0..=1, default_missing_value = "", conflicts_with_all = ["script", "interactive"])]
    pty: Option<PathBuf>,
    /// The board's PELCO port (UART4, the STM32 board's RS-485 USART3) on
    /// a raw pseudo-terminal for a PELCO-D / PELCO-P client (its path is
    /// printed; with PATH also a symlink to it).
    #[arg(long, num_args = 0..=1, default_missing_value = "")]
    pelco_pty: Option<PathBuf>,
    /// Print the board's log channel on stderr.
    #[arg(long)]
    log: bool,
    /// Run the scenarios of tests/scenarios on the board and check them,
    /// as `cargo xtask test` does (no other option applies).
    #[arg(long, conflicts_with_all = ["script", "interactive"])]
    pub scenarios: bool,
    /// The board with its galvo DAC stream (a timer interrupt consumes the
    /// galvo loop's double buffer at the sample rate): `target galvo`
    /// works, and the galvo loop runs on the emulated M4.
    #[arg(long)]
    galvo_dac: bool,
    /// laser-app's logs as defmt frames on UART3, decoded with
    /// defmt-decoder against the image (printed with --log) instead of
    /// the plain-text records.
    #[arg(long)]
    defmt_log: bool,
    /// Measure the board (image size, instructions per command and per
    /// second of holding, peak stack per task, the log channel's cost).
    #[arg(long, conflicts_with_all = ["script", "interactive", "scenarios"])]
    measure: bool,
}

/// Builds the board's release image with the default features; its path.
pub fn build_image() -> Result<PathBuf> {
    build_image_with(&[], false)
}

/// Builds the board's release image with `features` (after
/// `--no-default-features` when `no_default`); its path (a copy named
/// after the features).
pub fn build_image_with(features: &[&str], no_default: bool) -> Result<PathBuf> {
    crate::bench_m4::qemu::ensure_qemu()?;
    ensure_flip_link()?;
    let mut args = vec!["build", "--release", "--target", TARGET];
    if no_default {
        args.push("--no-default-features");
    }
    let joined = features.join(",");
    if !features.is_empty() {
        args.extend(["--features", joined.as_str()]);
    }
    crate::bench_m4::cargo_in(MANIFEST, &args)?;
    let built = target_dir().join(TARGET).join("release").join("qemu-m4");
    // Cargo writes every feature set to the same file: keep a copy per
    // set, so images built one after the other (`--scenarios`) stay apart.
    let mut name = String::from("qemu-m4-");
    name.push_str(if no_default { "no-default" } else { "default" });
    for feature in features {
        name.push('-');
        name.push_str(feature);
    }
    let copy = built.with_file_name(name);
    std::fs::copy(&built, &copy)
        .with_context(|| format!("cannot copy {} to {}", built.display(), copy.display()))?;
    Ok(copy)
}

/// The script text: the file, stdin (`-` or piped), or nothing when
/// interactive.
fn script_text(args: &QemuArgs) -> Result<String> {
    let read_stdin = || -> Result<String> {
        let mut text = String::new();
        std::io::stdin()
            .read_to_string(&mut text)
            .context("cannot read the script from stdin")?;
        Ok(text)
    };
    match &args.script {
        _ if args.interactive || args.pty.is_some() => Ok(String::new()),
        Some(path) if path.as_os_str() == "-" => read_stdin(),
        Some(path) => std::fs::read_to_string(path)
            .with_context(|| format!("cannot read script {}", path.display())),
        None if std::io::stdin().is_terminal() => {
            bail!("give a script (--script FILE, or pipe it in) or --interactive")
        }
        None => read_stdin(),
    }
}

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
            pty::forward_typed(&machine, from_host)?;
            pty::wait_for_stop(&stop, deadline);
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

/// Runs `cargo xtask qemu`.
pub fn run(args: QemuArgs) -> Result<ExitCode> {
    if args.measure {
        return measure::measure().map(|()| ExitCode::SUCCESS);
    }
    let text = script_text(&args)?;
    let steps = parse_board_script(&text)?;
    let (faults, slow_factor) = crate::sim::parse_faults(&args.faults)?;
    let max_time_s = match args.max_time_s {
        Some(s) if s.is_finite() && s > 0.0 => s,
        Some(_) => bail!("--max-time-s must be positive"),
        None if args.interactive || args.pty.is_some() => 3.2e7,
        None => 600.0,
    };
    let mut features = Vec::new();
    if args.galvo_dac {
        features.push("galvo-dac");
    }
    if steps
        .iter()
        .any(|s| matches!(s, BoardStep::Script(step) if step.uses_laser_controls()))
    {
        // `@interlock` / `@key`: a board with the laser controls.
        features.push("laser-controls");
    }
    if args.defmt_log {
        features.push("defmt-log");
    }
    let elf = build_image_with(&features, args.defmt_log)?;
    if args.interactive {
        eprintln!("xtask qemu: type commands (help lists them); Ctrl-D ends the run");
    }
    let mut options = MachineOptions {
        faults,
        slow_factor,
        echo: true,
        echo_log: args.log,
        console_tee: None,
        pelco: None,
    };
    let mut open_pty = None;
    let pelco_pty = match &args.pelco_pty {
        Some(link) => {
            let link = (!link.as_os_str().is_empty()).then_some(link.as_path());
            let (pty, bridge) = pty::open(link)?;
            eprintln!("xtask qemu: PELCO port on {}", pty.path.display());
            options.pelco = Some(machine::PelcoWire {
                to_host: bridge.to_host,
                from_host: Arc::new(std::sync::Mutex::new(bridge.from_host)),
            });
            Some(pty)
        }
        None => None,
    };
    let drive = if let Some(link) = &args.pty {
        let link = (!link.as_os_str().is_empty()).then_some(link.as_path());
        let (pty, bridge) = pty::open(link)?;
        eprintln!(
            "xtask qemu: console on {} (Ctrl-C ends the run)",
            pty.path.display()
        );
        let stop = Arc::new(AtomicBool::new(false));
        laser_sim::pty::stop_on_signals(stop.clone());
        options.console_tee = Some(bridge.to_host.clone());
        open_pty = Some(pty);
        Drive::Pty {
            from_host: bridge.from_host,
            stop,
        }
    } else if args.interactive {
        Drive::Interactive
    } else {
        Drive::Steps(steps)
    };
    let run = run_board(
        &elf,
        &options,
        drive,
        args.until_idle,
        Duration::from_secs_f64(max_time_s),
        args.trace.is_some(),
    )?;
    drop((open_pty, pelco_pty));
    write_outputs(&args, &run)?;
    eprintln!(
        "xtask qemu: ended at t = {:.3} s; {} boots, {} servo frames, {} laser switches, {} error replies",
        run.end_us as f64 / 1e6,
        run.log.boots,
        run.recording.frames.len(),
        run.log.laser_events.len(),
        run.terminal.error_replies
    );
    if args.until_idle && !run.succeeded(args.allow_errors) {
        if !run.script_done {
            eprintln!("xtask qemu: the script did not finish (time limit or no reply)");
        } else if !run.idle_at_end {
            eprintln!("xtask qemu: the sequencer was still busy when the run ended");
        }
        return Ok(ExitCode::FAILURE);
    }
    Ok(ExitCode::SUCCESS)
}

/// Writes the files the options ask for.
fn write_outputs(args: &QemuArgs, run: &BoardRun) -> Result<()> {
    if let Some(path) = &args.frames {
        std::fs::write(path, run.recording.frames_text())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.trace {
        std::fs::write(path, run.recording.trace_csv())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}
