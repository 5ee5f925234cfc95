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
mod board_run;
mod defmt_check;
mod defmt_log;
mod image;
mod machine;
mod measure;
mod pelco;
mod pty;
mod script;
mod servo_bus;
mod terminal;

use std::io::{IsTerminal, Read};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use anyhow::{Context, Result, bail};

pub use board_log::{BoardEvent, LogLine, parse_line};
pub use board_run::{BoardRun, Drive, run_board};
pub use defmt_check::check_channel as check_defmt_channel;
pub use image::{MANIFEST, build_image, build_image_with};
pub use machine::MachineOptions;
pub use pelco::check_port as check_pelco_port;
pub use pty::{check_console as check_pty_console, with_board_on_pty};
pub use script::{BoardStep, parse_board_script, split_at_resets};

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
