//! `cargo xtask sim`: run the firmware's tasks on the host against simulated
//! servos, in virtual time, and draw where the laser went.

mod bench_args;
#[cfg(test)]
mod doc_commands;

use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, anyhow, bail};
use laser_sim::executor::RunEnd;
use laser_sim::script::{DEMO_SCRIPT, parse_script};
use laser_sim::servo_port::{BusFaults, SilentWindow};
use laser_sim::world::{SimOptions, SimReport, run};

/// Options of `cargo xtask sim`.
#[derive(clap::Args, Debug)]
pub struct SimArgs {
    /// Script of command lines (`wait <ms>` pauses; `#` comments;
    /// `@stall-read <ms>` stops the host reading replies for a while,
    /// `@type-ahead <line>` types without waiting for the reply, `@button`
    /// presses the stop button, `@unplug-servo <slot>` / `@plug-servo
    /// <slot>` unplug and plug back a servo's cable); `-`
    /// reads it from stdin. Without it, piped stdin is the script, and a
    /// terminal or empty stdin runs the demo (writing sim.svg).
    #[arg(long)]
    script: Option<PathBuf>,
    /// Write the drawing (board, grid, laser path, dwell points) as SVG.
    #[arg(long)]
    svg: Option<PathBuf>,
    /// Write every servo-bus frame: `t_ms tx|rx hex-bytes`.
    #[arg(long)]
    frames: Option<PathBuf>,
    /// Write the spot trace as CSV `t_ms,x_cm,y_cm,laser`.
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Write every galvo DAC sample as CSV `k,t_s,dac_x,dac_y,laser`.
    #[arg(long)]
    dac: Option<PathBuf>,
    /// Write every stepper STEP/DIR edge as CSV `t_ns,axis,pin,level`.
    #[arg(long)]
    steps: Option<PathBuf>,
    /// Write every dwell as a measurement for `cargo xtask calib fit`
    /// (CSV `x,y,dx,dy`, mm: commanded point, spot minus commanded).
    #[arg(long)]
    dwells: Option<PathBuf>,
    /// Galvo loop compute time per DAC sample, ns (models a slower CPU:
    /// above the 10 µs sample period the loop underruns).
    #[arg(long, default_value_t = 0)]
    galvo_cost_ns: u64,
    /// Fit the laser controls (remote interlock, key switch, emission
    /// indicator; bench wiring: closed and on): no laser lights before
    /// `arm` (`docs/laser-safety.md`). A script with `@interlock` or `@key`
    /// steps fits them anyway.
    #[arg(long)]
    laser_controls: bool,
    /// Inject a fault: `servo-silent:<id>@<t_ms>[-<end_ms>]`, `servo-corrupt:<probability>`
    /// (per response byte), `servo-forge:<probability>` (per angle response: a wrong angle
    /// with a valid checksum), `servo-slow:<factor>` (repeatable).
    #[arg(long = "fault")]
    faults: Vec<String>,
    /// The ids the simulated servos on the bus have at power-up, in slot
    /// order (yaw, pitch, any more), e.g. `0,0` for two servos as they
    /// ship (default: the gimbal's ids, 0 and 1). `@unplug-servo <slot>` /
    /// `@plug-servo <slot>` in the script unplug and plug back a cable.
    #[arg(long, value_name = "ID,ID,…", value_delimiter = ',')]
    servo_ids: Vec<u8>,
    /// Run until the script has ended and the sequencer is idle; exit 1 if
    /// any command got `error:` (unless --allow-errors).
    #[arg(long)]
    until_idle: bool,
    /// With --until-idle: `error:` replies do not fail the run.
    #[arg(long)]
    allow_errors: bool,
    /// Pace with the wall clock instead of virtual time.
    #[arg(long)]
    realtime: bool,
    /// Type commands on stdin as the simulation runs in real time, like a
    /// serial terminal on the board (end with Ctrl-D). Implies --realtime.
    #[arg(long, conflicts_with = "script")]
    interactive: bool,
    /// Serve the console on a pseudo-terminal in real time, so any serial
    /// program (picocom, a G-code sender) connects as to the board; prints
    /// the device path, and makes PATH a symlink to it when given. Runs
    /// until Ctrl-C / SIGTERM (or --max-time-s), then writes the outputs.
    #[arg(long, num_args = 0..=1, default_missing_value = "", conflicts_with_all = ["script", "interactive"])]
    pty: Option<PathBuf>,
    /// Serve the board's PELCO port (the RS-485 UART: PELCO-D / PELCO-P
    /// frames) on a pseudo-terminal for a PTZ client or a CCTV keyboard's
    /// adapter; prints the device path, and makes PATH a symlink to it
    /// when given. Real time (implies --realtime); usually with --pty.
    #[arg(long, num_args = 0..=1, default_missing_value = "")]
    pelco_pty: Option<PathBuf>,
    /// Publish where the spot really lands and whether the laser is lit
    /// to FILE (default with `--pty LINK`: `LINK.spot`), one line replaced
    /// as it changes: what `cargo xtask calib camera --camera sim` renders.
    #[arg(long, value_name = "FILE", num_args = 0..=1)]
    spot_feed: Option<Option<PathBuf>>,
    /// Stop after this much simulated time, s (default 600; no limit with
    /// --interactive or --pty).
    #[arg(long)]
    max_time_s: Option<f64>,
    /// Check the safety invariants after the run (laser dark within 1 ms
    /// of stop/fault/button/underrun, never lit while moving, one reply
    /// per line, no task step over 1 ms of CPU time, lit samples on the
    /// G-code path and on the patterns' figures, motions ending in time,
    /// the laser controls; docs/safety-checker.md); print every
    /// violation and exit 1 on any.
    #[arg(long)]
    check_safety: bool,
    /// Log level of the firmware logs on stderr (error, warn, info, debug, trace, off).
    #[arg(long, default_value = "info")]
    log: String,
    /// How the simulated bench is built and set.
    #[command(flatten)]
    bench: bench_args::BenchArgs,
}

/// Parses the `--fault` specs.
pub fn parse_faults(specs: &[String]) -> Result<(BusFaults, f64)> {
    let mut faults = BusFaults::default();
    let mut slow = 1.0;
    for spec in specs {
        let (kind, value) = spec
            .split_once(':')
            .with_context(|| format!("fault {spec:?}: expected <kind>:<value>"))?;
        match kind {
            "servo-silent" => {
                let (id, times) = value.split_once('@').with_context(|| {
                    format!("fault {spec:?}: expected servo-silent:<id>@<t_ms>[-<end_ms>]")
                })?;
                let id: u8 = id
                    .parse()
                    .with_context(|| format!("fault {spec:?}: bad servo id"))?;
                let (from, until) = match times.split_once('-') {
                    Some((from, until)) => (from, Some(until)),
                    None => (times, None),
                };
                let from_ms: u64 = from
                    .parse()
                    .with_context(|| format!("fault {spec:?}: bad start time"))?;
                let until_ms = until
                    .map(|t| t.parse::<u64>())
                    .transpose()
                    .with_context(|| format!("fault {spec:?}: bad end time"))?;
                if until_ms.is_some_and(|end| end <= from_ms) {
                    bail!("fault {spec:?}: the silence must end after it starts");
                }
                faults.silent.push(SilentWindow {
                    id,
                    from_ms,
                    until_ms,
                });
            }
            "servo-corrupt" | "servo-forge" => {
                let p: f64 = value
                    .parse()
                    .with_context(|| format!("fault {spec:?}: bad probability"))?;
                if !(0.0..=1.0).contains(&p) {
                    bail!("fault {spec:?}: probability must be in [0, 1]");
                }
                if kind == "servo-forge" {
                    faults.forge_probability = p;
                } else {
                    faults.corrupt_probability = p;
                }
            }
            "servo-slow" => {
                let f: f64 = value
                    .parse()
                    .with_context(|| format!("fault {spec:?}: bad factor"))?;
                if !(1.0..=100.0).contains(&f) {
                    bail!("fault {spec:?}: factor must be in [1, 100]");
                }
                slow = f;
            }
            other => {
                bail!(
                    "unknown fault kind {other:?} (servo-silent, servo-corrupt, servo-forge, servo-slow)"
                )
            }
        }
    }
    Ok((faults, slow))
}

fn read_stdin() -> Result<String> {
    let mut text = String::new();
    std::io::stdin()
        .read_to_string(&mut text)
        .context("cannot read the script from stdin")?;
    Ok(text)
}

/// The script to run and whether it is the demo (no script given).
fn script_text(args: &SimArgs) -> Result<(String, bool)> {
    let script_text = match &args.script {
        _ if args.interactive || args.pty.is_some() => String::new(),
        Some(path) if path.as_os_str() == "-" => read_stdin()?,
        Some(path) => std::fs::read_to_string(path)
            .with_context(|| format!("cannot read script {}", path.display()))?,
        // Piped lines are the script; a terminal or empty input runs the demo.
        None if std::io::IsTerminal::is_terminal(&std::io::stdin()) => String::new(),
        None => read_stdin()?,
    };
    let demo = !args.interactive
        && args.pty.is_none()
        && args.script.is_none()
        && script_text.trim().is_empty();
    let script_text = if demo {
        DEMO_SCRIPT.to_owned()
    } else {
        script_text
    };
    Ok((script_text, demo))
}

/// A run as the options describe it, ready to go.
struct Prepared {
    options: SimOptions,
    /// Where the drawing goes (the demo draws `sim.svg`).
    svg: Option<PathBuf>,
    until_idle: bool,
    bench: laser_sim::bench::BenchBuild,
    /// The script's lines, for the microstep hint.
    typed: Vec<String>,
}

/// Reads the script and turns the options into the simulator's.
fn prepare(args: &SimArgs) -> Result<Prepared> {
    let (script_text, demo) = script_text(args)?;
    let script = parse_script(&script_text)?;
    let (faults, slow_factor) = parse_faults(&args.faults)?;
    let svg = args
        .svg
        .clone()
        .or_else(|| demo.then(|| PathBuf::from("sim.svg")));
    let until_idle = args.until_idle || demo;
    let max_time_s = match args.max_time_s {
        Some(s) if s.is_finite() && s > 0.0 => s,
        Some(_) => bail!("--max-time-s must be positive"),
        // A year of simulated time: no limit in practice.
        None if args.interactive || args.pty.is_some() => 3.2e7,
        None => 600.0,
    };
    if args.interactive {
        eprintln!("xtask sim: type commands (help lists them); Ctrl-D ends the simulation");
    }
    if demo {
        eprintln!("xtask sim: no script given, running the demo:\n{DEMO_SCRIPT}");
    }
    let pty = args.pty.as_ref().map(|link| {
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        laser_sim::pty::stop_on_signals(stop.clone());
        laser_sim::pty::PtyOptions {
            link: (!link.as_os_str().is_empty()).then(|| link.clone()),
            stop,
        }
    });
    let spot_feed = match (&args.spot_feed, &args.pty) {
        (Some(Some(file)), _) => Some(file.clone()),
        (Some(None), Some(link)) if !link.as_os_str().is_empty() => {
            Some(laser_sim::spot_feed::beside(link))
        }
        (Some(_), _) => bail!("--spot-feed needs a FILE, or --pty with a LINK"),
        (None, _) => None,
    };
    let bench = args.bench.build();
    let options = bench
        .apply(SimOptions {
            script,
            pty,
            pelco_pty: args
                .pelco_pty
                .as_ref()
                .map(|link| laser_sim::pelco_port::PelcoPtyOptions {
                    link: (!link.as_os_str().is_empty()).then(|| link.clone()),
                }),
            realtime: args.realtime
                || args.interactive
                || args.pty.is_some()
                || args.pelco_pty.is_some(),
            interactive: args.interactive,
            until_idle,
            faults,
            slow_factor,
            max_time_ms: (max_time_s * 1000.0) as u64,
            echo: true,
            galvo_cost_ns_per_sample: args.galvo_cost_ns,
            laser_controls: args.laser_controls,
            servo_ids: (!args.servo_ids.is_empty()).then(|| args.servo_ids.clone()),
            spot_feed,
            ..SimOptions::default()
        })
        .map_err(|e| anyhow!("bench options: {e}"))?;
    Ok(Prepared {
        options,
        svg,
        until_idle,
        bench,
        typed: script_text.lines().map(str::to_owned).collect(),
    })
}

/// Runs `cargo xtask sim`.
pub fn run_sim(args: SimArgs) -> Result<ExitCode> {
    let level: log::LevelFilter = args.log.parse().map_err(|_| {
        anyhow::anyhow!(
            "bad --log level {:?} (off, error, warn, info, debug, trace)",
            args.log
        )
    })?;
    laser_sim::logger::init(level);
    let prepared = prepare(&args)?;
    // A scripted run is deterministic in virtual time: with
    // `--check-safety` a long task step must recur in every run, so host
    // load alone cannot fail it (re-run at most twice, only when a step
    // was long). A real-time or terminal session runs once.
    let report = if args.check_safety && !prepared.options.realtime {
        let mut runs = 0;
        laser_sim::safety::steady_steps(|| {
            runs += 1;
            // The transcript is echoed once.
            run(SimOptions {
                echo: runs == 1,
                ..prepared.options.clone()
            })
        })
    } else {
        run(prepared.options.clone())
    };
    write_outputs(&args, prepared.svg.as_deref(), &report)?;
    print_summary(&report);
    if !report.stepper.edges.is_empty()
        && let Some(hint) = prepared
            .bench
            .microstep_hint(laser_sim::bench::microsteps_set_by(&prepared.typed))
    {
        eprintln!("xtask sim: hint: {hint}");
    }
    let unsafe_run = args.check_safety && !safety_holds(&report);
    Ok(exit_code(
        &report,
        prepared.until_idle,
        args.allow_errors,
        unsafe_run,
    ))
}

/// Writes the drawing and the files the options ask for.
fn write_outputs(args: &SimArgs, svg: Option<&Path>, report: &SimReport) -> Result<()> {
    if let Some(path) = svg {
        let drawing = laser_sim::render(report, "laser pointing controller — simulation")?;
        std::fs::write(path, drawing)
            .with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("xtask sim: drawing written to {}", path.display());
    }
    if let Some(path) = &args.frames {
        std::fs::write(path, report.recording.frames_text())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.trace {
        std::fs::write(path, report.recording.trace_csv())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.dac {
        std::fs::write(path, report.dac.csv())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.steps {
        std::fs::write(path, report.stepper.edges_csv())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.dwells {
        std::fs::write(path, report.recording.dwells_csv())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

/// The one-line summary of the run on stderr.
fn print_summary(report: &SimReport) {
    eprintln!(
        "xtask sim: ended at t = {:.3} s ({:?}); {} dwell points, {} servo frames, {} galvo DAC samples, {} galvo underruns, {} error replies",
        report.end_time_us as f64 / 1e6,
        report.end,
        report.recording.dwells.len(),
        report.recording.frames.len(),
        report.dac.len(),
        report.galvo_underruns,
        report.transcript.error_replies
    );
    if let Some(worst) = report.recording.worst_dwell_error_mm() {
        eprintln!("xtask sim: worst dwell error (spot vs commanded point): {worst:.2} mm");
    }
    if !report.stepper.edges.is_empty() {
        eprint!("xtask sim: {}", report.stepper.report());
    }
}

/// Checks the run against the safety rules and prints the verdict and
/// each task's longest step; whether no rule was broken.
fn safety_holds(report: &SimReport) -> bool {
    let violations = laser_sim::safety::check(report);
    eprint!("xtask sim: {}", laser_sim::safety::report_text(&violations));
    for task in &report.task_steps {
        eprintln!(
            "xtask sim:   {:<18} {:>9} steps, longest {:.3} ms CPU at {:.3} ms",
            task.name,
            task.polls,
            task.max_cpu_ns as f64 / 1e6,
            task.max_at_us as f64 / 1000.0
        );
    }
    violations.is_empty()
}

/// Failure on a livelock, an unfinished or failed run (with
/// `--until-idle`) or a broken safety rule.
fn exit_code(
    report: &SimReport,
    until_idle: bool,
    allow_errors: bool,
    unsafe_run: bool,
) -> ExitCode {
    if report.end == RunEnd::Livelock {
        eprintln!(
            "xtask sim: a task kept running without letting time pass (busy loop); run stopped"
        );
        return ExitCode::FAILURE;
    }
    if until_idle && !report.succeeded(allow_errors) {
        if !report.idle_at_end {
            eprintln!("xtask sim: the sequencer was still busy when the run ended");
        }
        return ExitCode::FAILURE;
    }
    if unsafe_run {
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}

#[cfg(test)]
mod tests;
