//! Running a libFuzzer binary and reading its statistics.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use anyhow::{Context, Result};

use crate::toolchain::{target_dir, workspace_root};

/// Longest input generated, bytes: longer than a console line burst, a
/// settings record or a measurement file needs.
pub(super) const MAX_INPUT_LEN: usize = 4096;
/// Host triple the fuzz targets are built for (cargo-fuzz's default).
pub(super) const FUZZ_TRIPLE: &str = "x86_64-unknown-linux-gnu";

/// The fuzz binary of `target` built by `cargo fuzz build`.
fn fuzz_binary(target: &str) -> PathBuf {
    target_dir().join(FUZZ_TRIPLE).join("release").join(target)
}

/// Executions and wall time of one libFuzzer run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunStats {
    /// Inputs executed.
    pub executions: u64,
    /// Seconds fuzzed (`None` when the run ended early without saying).
    pub seconds: Option<u64>,
}

/// Runs the fuzz binary of `target` with libFuzzer `options` on corpus
/// `dirs` (new inputs go to the first), its output saved in `log_path`
/// (libFuzzer is chatty; the progress lines are echoed); returns whether
/// it held and its output.
pub(super) fn run_fuzzer(
    target: &str,
    options: &[String],
    dirs: &[&Path],
    log_path: &Path,
) -> Result<(bool, String)> {
    let binary = fuzz_binary(target);
    let mut args: Vec<String> = options.to_vec();
    args.extend(dirs.iter().map(|d| d.to_string_lossy().into_owned()));
    println!("$ {} {}", binary.display(), args.join(" "));
    let output = Command::new(&binary)
        .args(&args)
        .current_dir(workspace_root())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| format!("could not start {}", binary.display()))?;
    let mut child = output;
    let mut log = std::fs::File::create(log_path)
        .with_context(|| format!("cannot write {}", log_path.display()))?;
    // libFuzzer reports on stderr; drain stdout on a thread so neither
    // pipe can fill up.
    let stdout = child.stdout.take().context("no stdout pipe")?;
    let out_thread = std::thread::spawn(move || {
        let mut text = String::new();
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            text.push_str(&line);
            text.push('\n');
        }
        text
    });
    let mut text = String::new();
    if let Some(stderr) = child.stderr.take() {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            writeln!(log, "{line}").ok();
            if line.contains("INITED") || line.contains("pulse") || line.starts_with("Done ") {
                println!("   {line}");
            }
            text.push_str(&line);
            text.push('\n');
        }
    }
    let status = child.wait().context("the fuzzer did not finish")?;
    let stdout = out_thread.join().unwrap_or_default();
    write!(log, "{stdout}").ok();
    text.push_str(&stdout);
    Ok((status.success(), text))
}

/// Executions and seconds of a libFuzzer run, from its final statistics
/// (`stat::number_of_executed_units`) or its `Done N runs in S second(s)`
/// line.
pub fn parse_run_stats(log: &str) -> Option<RunStats> {
    let done = log.lines().rev().find_map(|line| {
        let rest = line.strip_prefix("Done ")?;
        let (runs, rest) = rest.split_once(" runs in ")?;
        let (secs, _) = rest.split_once(' ')?;
        Some(RunStats {
            executions: runs.trim().parse().ok()?,
            seconds: Some(secs.trim().parse().ok()?),
        })
    });
    let executed = log.lines().rev().find_map(|line| {
        line.strip_prefix("stat::number_of_executed_units:")
            .and_then(|n| n.trim().parse::<u64>().ok())
    });
    // A run that crashed has no `Done` line: its time is not known.
    done.or(executed.map(|executions| RunStats {
        executions,
        seconds: None,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_executions_from_a_finished_run() {
        let log = "#1048576\tpulse  cov: 812 ft: 3012 corp: 140/9Kb exec/s: 34952 rss: 61Mb\n\
                   Done 2093113 runs in 61 second(s)\n\
                   stat::number_of_executed_units: 2093113\n\
                   stat::average_exec_per_sec:     34313\n";
        assert_eq!(
            parse_run_stats(log),
            Some(RunStats {
                executions: 2_093_113,
                seconds: Some(61)
            })
        );
    }

    #[test]
    fn reads_executions_from_a_crashed_run() {
        // A crash ends the run without `Done`; the final stats remain.
        let log = "==123== ERROR: libFuzzer: deadly signal\n\
                   stat::number_of_executed_units: 4242\n";
        assert_eq!(
            parse_run_stats(log),
            Some(RunStats {
                executions: 4242,
                seconds: None
            })
        );
        assert_eq!(parse_run_stats("no statistics here"), None);
    }
}
