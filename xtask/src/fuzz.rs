//! `cargo xtask fuzz [--target NAME | --all] [--time SECONDS]`: runs the
//! cargo-fuzz targets of `tests/fuzz/` (nightly, libFuzzer) for a while
//! each, then merges the inputs that reached new code into the committed
//! corpus `tests/fuzz/corpus/<target>/`. `cargo xtask test` replays that
//! corpus, and any crash input saved in `tests/fuzz/artifacts/<target>/`,
//! through the same property checks on stable (`tests/fuzz-props`).
//!
//! Installs the nightly toolchain and cargo-fuzz when they are missing.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use anyhow::{Context, Result, bail};

use crate::toolchain::{run, target_dir, workspace_root};

/// Longest input generated, bytes: longer than a console line burst, a
/// settings record or a measurement file needs.
const MAX_INPUT_LEN: usize = 4096;
/// Corpus size above which `cargo xtask fuzz` warns (the corpus is
/// committed: keep it to a few hundred small files).
const CORPUS_FILE_LIMIT: usize = 400;
/// Host triple the fuzz targets are built for (cargo-fuzz's default).
const FUZZ_TRIPLE: &str = "x86_64-unknown-linux-gnu";

/// `cargo xtask fuzz …`
#[derive(clap::Args, Debug)]
pub struct FuzzArgs {
    /// Fuzz this target only (see `tests/fuzz/Cargo.toml`).
    #[arg(long, conflicts_with = "all")]
    target: Option<String>,
    /// Fuzz every target (the default without `--target`).
    #[arg(long)]
    all: bool,
    /// Seconds of fuzzing per target.
    #[arg(long, default_value_t = 30)]
    time: u64,
}

/// What one target's run did.
#[derive(Debug)]
struct Outcome {
    target: String,
    stats: Option<RunStats>,
    corpus_before: usize,
    corpus_after: usize,
    added: usize,
    /// `None` when the run held; the reason (and the log) when it did not.
    failure: Option<String>,
}

/// Executions and wall time of one libFuzzer run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunStats {
    /// Inputs executed.
    pub executions: u64,
    /// Seconds fuzzed (`None` when the run ended early without saying).
    pub seconds: Option<u64>,
}

fn fuzz_dir() -> PathBuf {
    workspace_root().join("tests").join("fuzz")
}

/// Runs `cargo xtask fuzz`.
pub fn fuzz(args: FuzzArgs) -> Result<()> {
    if args.time == 0 {
        bail!("--time must be at least 1 second");
    }
    ensure_fuzz_tools()?;
    let known = list_targets()?;
    let targets = match &args.target {
        Some(name) if known.contains(name) => vec![name.clone()],
        Some(name) => bail!(
            "no fuzz target `{name}`; the targets are: {}",
            known.join(", ")
        ),
        None => known,
    };
    build_targets(args.target.as_deref())?;
    let mut outcomes = Vec::new();
    for target in &targets {
        outcomes.push(fuzz_target(target, args.time)?);
    }
    println!();
    println!(
        "{:<18} {:>12} {:>6} {:>10} {:>16}  result",
        "target", "executions", "s", "exec/s", "corpus"
    );
    for o in &outcomes {
        let (execs, secs, rate) = match o.stats {
            Some(RunStats {
                executions,
                seconds: Some(seconds),
            }) => (
                executions.to_string(),
                seconds.to_string(),
                (executions / seconds.max(1)).to_string(),
            ),
            Some(RunStats {
                executions,
                seconds: None,
            }) => (executions.to_string(), "?".into(), "?".into()),
            None => ("?".into(), "?".into(), "?".into()),
        };
        let corpus = format!("{}→{} (+{})", o.corpus_before, o.corpus_after, o.added);
        let result = o.failure.as_deref().unwrap_or("ok");
        println!(
            "{:<18} {execs:>12} {secs:>6} {rate:>10} {corpus:>16}  {result}",
            o.target
        );
        if o.corpus_after > CORPUS_FILE_LIMIT {
            println!(
                "  {}: {} corpus files, over {CORPUS_FILE_LIMIT}: the target reaches much \
                 more code than before; check that the corpus should grow that much",
                o.target, o.corpus_after
            );
        }
    }
    let failed: Vec<&str> = outcomes
        .iter()
        .filter(|o| o.failure.is_some())
        .map(|o| o.target.as_str())
        .collect();
    if !failed.is_empty() {
        bail!(
            "fuzzing found failures in {}: the inputs are in tests/fuzz/artifacts/<target>/; \
             fix the cause and keep the input there as a regression (`cargo xtask test` replays it)",
            failed.join(", ")
        );
    }
    Ok(())
}

/// Installs the nightly toolchain and cargo-fuzz when missing.
fn ensure_fuzz_tools() -> Result<()> {
    let toolchains = Command::new("rustup")
        .args(["toolchain", "list"])
        .output()
        .context("`rustup` not found: install Rust with rustup (https://rustup.rs)")?;
    let toolchains = String::from_utf8_lossy(&toolchains.stdout);
    if !toolchains.lines().any(|l| l.starts_with("nightly")) {
        println!("cargo-fuzz needs the nightly toolchain, which is missing: installing it");
        run(
            "rustup",
            &["toolchain", "install", "nightly", "--profile", "minimal"],
        )?;
    }
    let has_cargo_fuzz = Command::new("cargo")
        .args(["+nightly", "fuzz", "--version"])
        .current_dir(workspace_root())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !has_cargo_fuzz {
        println!("cargo-fuzz is missing: installing it");
        run("cargo", &["install", "cargo-fuzz", "--locked"])?;
    }
    Ok(())
}

/// The targets declared in `tests/fuzz/Cargo.toml`.
fn list_targets() -> Result<Vec<String>> {
    let dir = fuzz_dir().to_string_lossy().into_owned();
    let out = Command::new("cargo")
        .args(["+nightly", "fuzz", "list", "--fuzz-dir", &dir])
        .current_dir(workspace_root())
        .output()
        .context("could not run `cargo fuzz list`")?;
    if !out.status.success() {
        bail!(
            "`cargo fuzz list` failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let targets: Vec<String> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .map(str::to_owned)
        .collect();
    if targets.is_empty() {
        bail!("no fuzz targets in {dir}");
    }
    Ok(targets)
}

/// The fuzz binary of `target` built by `cargo fuzz build`.
fn fuzz_binary(target: &str) -> PathBuf {
    target_dir().join(FUZZ_TRIPLE).join("release").join(target)
}

/// Builds the fuzz targets (all, or `only`) once: the runs below start
/// the binaries directly, so cargo does not rebuild between them.
fn build_targets(only: Option<&str>) -> Result<()> {
    let fuzz = fuzz_dir().to_string_lossy().into_owned();
    let target_dir = target_dir().to_string_lossy().into_owned();
    let mut args = vec![
        "+nightly",
        "fuzz",
        "build",
        "--fuzz-dir",
        &fuzz,
        "--target-dir",
        &target_dir,
        "--target",
        FUZZ_TRIPLE,
    ];
    args.extend(only);
    run("cargo", &args)
}

/// Fuzzes one target for `seconds`, then merges what it found into the
/// committed corpus.
fn fuzz_target(target: &str, seconds: u64) -> Result<Outcome> {
    let fuzz = fuzz_dir();
    let corpus = fuzz.join("corpus").join(target);
    let artifacts = fuzz.join("artifacts").join(target);
    for dir in [&corpus, &artifacts] {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    // New inputs go to a scratch folder; the merge below keeps only those
    // that reach code the corpus does not.
    let work = target_dir().join("fuzz-work").join(target);
    let _ = std::fs::remove_dir_all(&work);
    let found = work.join("found");
    std::fs::create_dir_all(&found)
        .with_context(|| format!("cannot create {}", found.display()))?;
    let corpus_before = list_files(&corpus);

    println!("== fuzzing `{target}` for {seconds} s");
    let mut options = vec![
        format!("-max_total_time={seconds}"),
        format!("-max_len={MAX_INPUT_LEN}"),
        "-print_final_stats=1".to_owned(),
        format!("-artifact_prefix={}/", artifacts.display()),
    ];
    let dict = fuzz.join("dict").join(format!("{target}.dict"));
    if dict.exists() {
        options.push(format!("-dict={}", dict.display()));
    }
    let log_path = work.join("fuzz.log");
    let (held, log) = run_fuzzer(target, &options, &[&found, &corpus], &log_path)?;
    let stats = parse_run_stats(&log);
    let failure = if held {
        None
    } else {
        let tail: Vec<&str> = log.lines().rev().take(40).collect();
        for line in tail.iter().rev() {
            println!("  | {line}");
        }
        Some(format!(
            "FAILED: input saved in {}, log {}",
            artifacts.display(),
            log_path.display()
        ))
    };
    let corpus_after = minimise_corpus(target, &corpus, &found, &work)?;
    let added = corpus_after
        .iter()
        .filter(|f| !corpus_before.contains(f))
        .count();
    match stats {
        Some(s) => println!(
            "   {target}: {} executions in {} s; corpus {} → {} files ({added} new)",
            s.executions,
            s.seconds.map_or("?".to_owned(), |s| s.to_string()),
            corpus_before.len(),
            corpus_after.len()
        ),
        None => println!("   {target}: no run statistics in {}", log_path.display()),
    }
    Ok(Outcome {
        target: target.to_owned(),
        stats,
        corpus_before: corpus_before.len(),
        corpus_after: corpus_after.len(),
        added,
        failure,
    })
}

/// Replaces the committed corpus with its seeds (`seed-*`, kept always),
/// the other corpus files that reach edges the seeds do not, and the new
/// `found` inputs that reach edges none of those do (libFuzzer's merge,
/// edges only: hit counts would keep hundreds of near-duplicates).
/// Returns the new corpus's file names.
fn minimise_corpus(target: &str, corpus: &Path, found: &Path, work: &Path) -> Result<Vec<String>> {
    let merged = work.join("merged");
    std::fs::create_dir_all(&merged)
        .with_context(|| format!("cannot create {}", merged.display()))?;
    let old = work.join("old");
    std::fs::create_dir_all(&old).with_context(|| format!("cannot create {}", old.display()))?;
    for name in list_files(corpus) {
        let into = if name.starts_with("seed-") {
            &merged
        } else {
            &old
        };
        std::fs::copy(corpus.join(&name), into.join(&name))
            .with_context(|| format!("cannot copy {name}"))?;
    }
    let options = [
        "-merge=1".to_owned(),
        "-use_counters=0".to_owned(),
        format!("-max_len={MAX_INPUT_LEN}"),
    ];
    // The old corpus first, then the new inputs: a new input is kept only
    // for edges the corpus does not reach yet, so unchanged coverage keeps
    // the committed files as they are.
    for (step, from) in [("old", old.as_path()), ("new", found)] {
        let log_path = work.join(format!("merge-{step}.log"));
        let (ok, log) = run_fuzzer(target, &options, &[&merged, from], &log_path)?;
        if !ok {
            bail!(
                "merging the corpus of `{target}` failed (log {}):\n{}",
                log_path.display(),
                log.lines().rev().take(20).collect::<Vec<_>>().join("\n")
            );
        }
    }
    let keep = list_files(&merged);
    for name in list_files(corpus) {
        if !keep.contains(&name) {
            std::fs::remove_file(corpus.join(&name))
                .with_context(|| format!("cannot remove {name} from the corpus"))?;
        }
    }
    for name in &keep {
        let to = corpus.join(name);
        if !to.exists() {
            std::fs::copy(merged.join(name), &to)
                .with_context(|| format!("cannot add {name} to the corpus"))?;
        }
    }
    Ok(keep)
}

/// Sorted names of the files in `dir` (none when it does not exist).
fn list_files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(Result::ok)
                .filter(|e| e.path().is_file())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// Runs the fuzz binary of `target` with libFuzzer `options` on corpus
/// `dirs` (new inputs go to the first), its output saved in `log_path`
/// (libFuzzer is chatty; the progress lines are echoed); returns whether
/// it held and its output.
fn run_fuzzer(
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
