//! The simulator commands the docs show, run exactly as written: each
//! `cargo xtask sim …`, `cargo xtask calib fit …` and `cat … > …` line of
//! a doc's `sh` blocks is parsed by the real command-line parser and run
//! in order (files the repository has are read from it, the others are
//! written to a scratch folder), and the figures the doc states are
//! checked on the results.

use std::path::{Path, PathBuf};

use clap::Parser;
use laser_sim::world::{SimReport, run};

use super::{SimArgs, prepare};
use crate::calib::CalibArgs;
use crate::toolchain::workspace_root;

#[derive(Parser)]
struct SimCli {
    #[command(flatten)]
    args: SimArgs,
}

#[derive(Parser)]
struct CalibCli {
    #[command(flatten)]
    args: CalibArgs,
}

/// The command lines of `doc`'s ```` ```sh ```` blocks that start with
/// `cargo xtask sim`, `cargo xtask calib` or `cat`.
fn shown_commands(doc: &str) -> Vec<String> {
    let text = std::fs::read_to_string(workspace_root().join(doc)).expect("doc readable");
    let mut in_sh = false;
    let mut commands = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with("```") {
            in_sh = line == "```sh";
            continue;
        }
        if in_sh
            && ["cargo xtask sim", "cargo xtask calib", "cat "]
                .iter()
                .any(|p| line.starts_with(p))
        {
            commands.push(line.to_owned());
        }
    }
    commands
}

/// A path as the command names it: the repository's file when there is
/// one, else a file in `scratch`.
fn resolve(word: &str, scratch: &Path) -> String {
    let in_repo = workspace_root().join(word);
    let looks_like_file = !word.starts_with('-')
        && word.rsplit_once('.').is_some_and(|(stem, ext)| {
            !stem.is_empty() && ext.chars().all(|c| c.is_ascii_alphabetic())
        });
    if !looks_like_file || in_repo.exists() {
        if looks_like_file {
            return in_repo.display().to_string();
        }
        return word.to_owned();
    }
    scratch.join(word).display().to_string()
}

/// Runs `commands` in order: the report of each simulator run.
fn run_shown(commands: &[String], scratch: &Path) -> Vec<SimReport> {
    let mut reports = Vec::new();
    for command in commands {
        let words: Vec<String> = command
            .split_whitespace()
            .map(|w| resolve(w, scratch))
            .collect();
        match words
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>()
            .as_slice()
        {
            ["cargo", "xtask", "sim", rest @ ..] => {
                let cli =
                    SimCli::try_parse_from(std::iter::once("sim").chain(rest.iter().copied()))
                        .unwrap_or_else(|e| panic!("{command}: {e}"));
                let prepared = prepare(&cli.args).unwrap_or_else(|e| panic!("{command}: {e:#}"));
                let mut options = prepared.options;
                options.echo = false;
                let report = run(options);
                super::write_outputs(&cli.args, prepared.svg.as_deref(), &report)
                    .unwrap_or_else(|e| panic!("{command}: {e:#}"));
                assert!(
                    report.succeeded(false),
                    "{command}: {:?}",
                    report.transcript
                );
                reports.push(report);
            }
            ["cargo", "xtask", "calib", rest @ ..] => {
                let cli =
                    CalibCli::try_parse_from(std::iter::once("calib").chain(rest.iter().copied()))
                        .unwrap_or_else(|e| panic!("{command}: {e}"));
                let code =
                    crate::calib::run(cli.args).unwrap_or_else(|e| panic!("{command}: {e:#}"));
                assert_eq!(code, std::process::ExitCode::SUCCESS, "{command}");
            }
            ["cat", inputs @ .., ">", output] => {
                let text: String = inputs
                    .iter()
                    .map(|p| std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{p}: {e}")))
                    .collect();
                std::fs::write(output, text).unwrap();
            }
            _ => panic!("a command this test does not know: {command}"),
        }
    }
    reports
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("xtask-doc-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn the_calibration_doc_commands_reproduce_its_figures() {
    let commands = shown_commands("docs/calibration.md");
    assert_eq!(commands.len(), 4, "{commands:?}");
    let dir = scratch("calibration");
    let reports = run_shown(&commands, &dir);
    let worst: Vec<f64> = reports
        .iter()
        .map(|r| r.recording.worst_dwell_error_mm().expect("dwells"))
        .collect();
    std::fs::remove_dir_all(&dir).ok();
    // The doc says 5.71 mm before and 0.40 mm after, to two decimals.
    assert_eq!(format!("{:.2}", worst[0]), "5.71", "{worst:?}");
    assert_eq!(format!("{:.2}", worst[1]), "0.40", "{worst:?}");
}

/// Distance of `(x, y)` cm from the stepper doc's three figures (the line
/// (−10, −6)→(9, 7), the circle about (1, −2) of radius 8 and the
/// rectangle (−9, −5)–(8, 6)), whichever is nearest, mm.
fn off_the_figures_mm(x: f64, y: f64) -> f64 {
    let (dx, dy) = (19.0_f64, 13.0_f64);
    let t = (((x + 10.0) * dx + (y + 6.0) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    let line = (x + 10.0 - t * dx).hypot(y + 6.0 - t * dy);
    let circle = ((x - 1.0).hypot(y + 2.0) - 8.0).abs();
    let to_h = |y0: f64| (y - y0).hypot(x.clamp(-9.0, 8.0) - x);
    let to_v = |x0: f64| (x - x0).hypot(y.clamp(-5.0, 6.0) - y);
    let rect = to_h(-5.0).min(to_h(6.0)).min(to_v(-9.0)).min(to_v(8.0));
    line.min(circle).min(rect) * 10.0
}

#[test]
fn the_stepper_doc_commands_reproduce_its_figures() {
    let commands = shown_commands("docs/stepper.md");
    assert_eq!(commands.len(), 2, "{commands:?}");
    let dir = scratch("stepper");
    let reports = run_shown(&commands, &dir);
    // The first writes fine.csv: every lit point within 0.1 mm.
    let trace = std::fs::read_to_string(dir.join("fine.csv")).expect("fine.csv written");
    std::fs::remove_dir_all(&dir).ok();
    let mut lit = 0;
    let mut worst: f64 = 0.0;
    for row in trace.lines().skip(1) {
        let f: Vec<&str> = row.split(',').collect();
        if f[3] == "1" {
            lit += 1;
            let (x, y): (f64, f64) = (f[1].parse().unwrap(), f[2].parse().unwrap());
            worst = worst.max(off_the_figures_mm(x, y));
        }
    }
    assert!(lit > 300, "{lit} lit points");
    assert!(worst <= 0.1, "worst {worst} mm");
    // The second: drivers at 256, firmware at 32 — an eighth of the travel.
    let mismatch = &reports[1];
    let spot = mismatch.recording.spot.last().expect("spot");
    assert!(
        (spot.x_cm - 1.0).abs() < 0.1,
        "goto 8 0 ends at x = {} cm",
        spot.x_cm
    );
    let bench = laser_sim::bench::BenchBuild {
        stepper_microsteps: 256,
        ..Default::default()
    };
    let script =
        std::fs::read_to_string(workspace_root().join("docs/examples/stepper-mismatch.txt"))
            .unwrap();
    let typed: Vec<String> = script.lines().map(str::to_owned).collect();
    let hint = bench
        .microstep_hint(laser_sim::bench::microsteps_set_by(&typed))
        .expect("a hint");
    assert!(hint.contains("set stepper.microsteps 256"), "{hint}");
}
