//! `cargo xtask <command>`: the project's one entry point for building,
//! testing, flashing and simulating, plus the geometry and planning tools.

mod bench_m4;
mod calib;
mod doctor;
mod fuzz;
mod gate;
mod hil;
#[cfg(test)]
mod import_cycles;
mod json_out;
mod kin;
mod path_remap;
mod plan;
mod qemu;
mod scenario;
mod serial;
mod sim;
mod size_gcode;
mod size_stack;
mod toolchain;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser, Debug)]
#[command(name = "xtask", about = "Laser pointing controller: project tasks")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// fmt check, clippy (host + target), all host tests, release firmware build and size budget.
    Test,
    /// Build the release firmware for thumbv7em-none-eabihf.
    Build,
    /// Check this machine for the first hour with a board: toolchain,
    /// flip-link, probe-rs, udev rules, probes, the board's console (and
    /// with --port, that the firmware answers and matches this checkout).
    Doctor(doctor::DoctorArgs),
    /// The hot paths on the Cortex-M4F ISA (QEMU mps2-an386, -icount): instruction counts, µs, budgets.
    BenchM4,
    /// Build the release firmware and flash it with `probe-rs run` (streams defmt logs).
    Flash,
    /// Print the release firmware's size (text/data/bss) against the budget.
    Size,
    /// The hardware acceptance run: the shared scenarios against a board
    /// over its serial console, a pass/fail table and a JSON report.
    Hil(hil::HilArgs),
    /// Run the firmware tasks on the host against simulated servos (virtual time).
    Sim(sim::SimArgs),
    /// Run the firmware on QEMU's mps2-an386 (Cortex-M4F) against the simulator's servos.
    Qemu(qemu::QemuArgs),
    /// Gimbal kinematics: `kin ik`, `kin fk`, `kin grid-error`.
    Kin(kin::KinArgs),
    /// Error-model calibration: `calib fit --input FILE.csv`.
    Calib(calib::CalibArgs),
    /// Galvo jump planning: `plan jump …`, `plan compare`.
    Plan(plan::PlanArgs),
    /// Run the cargo-fuzz targets (nightly; installed when missing) and
    /// merge new inputs into tests/fuzz/corpus.
    Fuzz(fuzz::FuzzArgs),
    /// Real G-code senders (PyPI's grbl-streamer and pygrbl-streamer,
    /// npm's cncjs headless; installed into target/senders when missing)
    /// stream a laser CAM job to the simulator through its PTY console,
    /// and a PELCO-D client (PyPI's pyptzcontroller) drives its PELCO
    /// port's PTY in PELCO-D and PELCO-P, in real time (~4 min).
    Senders,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if builds_for_the_target(&cli.command)
        && let Err(err) = path_remap::apply()
    {
        eprintln!("xtask: error: {err:#}");
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        Command::Test => gate::test().map(|()| ExitCode::SUCCESS),
        Command::Build => toolchain::build_firmware().map(|_| ExitCode::SUCCESS),
        Command::Doctor(args) => doctor::run(args),
        Command::BenchM4 => bench_m4::bench_m4().map(|_table| ExitCode::SUCCESS),
        Command::Flash => toolchain::flash().map(|()| ExitCode::SUCCESS),
        Command::Size => toolchain::size().map(|()| ExitCode::SUCCESS),
        Command::Sim(args) => sim::run_sim(args),
        Command::Hil(args) => hil::run(args),
        // The scenarios on the QEMU board are the gate's part there.
        Command::Qemu(args) if args.scenarios => gate::run_on_qemu().map(|()| ExitCode::SUCCESS),
        Command::Qemu(args) => qemu::run(args),
        Command::Kin(args) => kin::run(args),
        Command::Calib(args) => calib::run(args),
        Command::Plan(args) => plan::run(args),
        Command::Fuzz(args) => fuzz::fuzz(args).map(|()| ExitCode::SUCCESS),
        Command::Senders => toolchain::run(
            "cargo",
            &[
                "test",
                "-p",
                "system-tests",
                "--test",
                "gcode_senders",
                "--test",
                "pelco_client",
                "--",
                "--ignored",
                "--test-threads",
                "1",
                "--nocapture",
            ],
        )
        .map(|()| ExitCode::SUCCESS),
    };
    match result {
        Ok(code) => code,
        Err(err) => {
            eprintln!("xtask: error: {err:#}");
            ExitCode::FAILURE
        }
    }
}

/// Commands that build for the firmware target (their panic paths are
/// remapped so the image size does not depend on the machine).
fn builds_for_the_target(command: &Command) -> bool {
    matches!(
        command,
        Command::Test
            | Command::Build
            | Command::BenchM4
            | Command::Flash
            | Command::Size
            | Command::Qemu(_)
    )
}
