//! `cargo xtask fuzz [--target NAME | --all] [--time SECONDS]`: runs the
//! cargo-fuzz targets of `tests/fuzz/` (nightly, libFuzzer) for a while
//! each, then merges the inputs that reached new code into the committed
//! corpus `tests/fuzz/corpus/<target>/`. `cargo xtask test` replays that
//! corpus, and any crash input saved in `tests/fuzz/artifacts/<target>/`,
//! through the same property checks on stable (`tests/fuzz-props`).
//!
//! Installs the nightly toolchain and cargo-fuzz when they are missing.

mod corpus;
mod libfuzzer;

use std::path::PathBuf;
use std::process::{Command, Stdio};

use anyhow::{Context, Result, bail};

use crate::toolchain::{run, target_dir, workspace_root};

use corpus::{list_files, minimise_corpus};
use libfuzzer::{FUZZ_TRIPLE, MAX_INPUT_LEN, RunStats, parse_run_stats, run_fuzzer};

/// Corpus size above which `cargo xtask fuzz` warns (the corpus is
/// committed: keep it to a few hundred small files).
const CORPUS_FILE_LIMIT: usize = 400;

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
