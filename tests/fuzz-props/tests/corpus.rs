//! Every saved fuzz input (`tests/fuzz/corpus/<target>/` and the crash
//! regressions in `tests/fuzz/artifacts/<target>/`) through the same
//! property checks as the fuzz targets, on stable: `cargo xtask test` keeps
//! what the fuzzer found. Each test also proves the committed seeds reach
//! what the target is about (every command word, every frame kind, an
//! accepted record, a realistic CSV).

use std::collections::BTreeSet;
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::path::{Path, PathBuf};

use fuzz_props::{TARGETS, calib, console, grbl, pelco, record, servo};

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz")
}

/// Files of `tests/fuzz/<kind>/<target>/` (none when it does not exist).
fn inputs(kind: &str, target: &str) -> Vec<PathBuf> {
    let dir = fuzz_dir().join(kind).join(target);
    let mut files: Vec<PathBuf> = match std::fs::read_dir(&dir) {
        Ok(entries) => entries
            .map(|e| e.expect("readable corpus folder").path())
            .filter(|p| p.is_file())
            .collect(),
        Err(_) => Vec::new(),
    };
    files.sort();
    files
}

/// Runs `check` on every corpus and regression input of `target`, naming
/// the file when a property fails; returns the summaries.
fn run_all<T>(target: &str, check: impl Fn(&[u8]) -> T) -> Vec<T> {
    assert!(TARGETS.contains(&target), "{target} is not a fuzz target");
    let corpus = inputs("corpus", target);
    assert!(
        !corpus.is_empty(),
        "no corpus in {}",
        fuzz_dir().join("corpus").join(target).display()
    );
    let mut summaries = Vec::new();
    for path in corpus.iter().chain(&inputs("artifacts", target)) {
        let data = std::fs::read(path).expect("readable corpus file");
        match catch_unwind(AssertUnwindSafe(|| check(&data))) {
            Ok(summary) => summaries.push(summary),
            Err(panic) => {
                eprintln!("property failed on {}", path.display());
                resume_unwind(panic);
            }
        }
    }
    summaries
}

#[test]
fn every_fuzz_target_is_declared_and_replayed_here() {
    // The `[[bin]]` names of the cargo-fuzz crate.
    let manifest = std::fs::read_to_string(fuzz_dir().join("Cargo.toml")).expect("fuzz manifest");
    let mut in_bin = false;
    let mut declared = Vec::new();
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            in_bin = line == "[[bin]]";
        } else if let Some(name) = line.strip_prefix("name = ").filter(|_| in_bin) {
            declared.push(name.trim_matches('"').to_owned());
        }
    }
    let mut expected: Vec<String> = TARGETS.iter().map(|t| (*t).to_owned()).collect();
    declared.sort();
    expected.sort();
    assert_eq!(declared, expected);
    for target in TARGETS {
        let source = fuzz_dir().join("fuzz_targets").join(format!("{target}.rs"));
        assert!(source.is_file(), "{}", source.display());
    }
}

#[test]
fn console_corpus_holds_and_covers_every_command() {
    let all = run_all("console", console::check);
    let commands: BTreeSet<&str> = all
        .iter()
        .flat_map(|s| s.commands.iter().copied())
        .collect();
    let every = [
        "help",
        "version",
        "status",
        "stop",
        "params",
        "target",
        "planner",
        "galvo status",
        "save",
        "pattern",
        "goto",
        "grid",
        "laser",
        "model",
        "set",
        "get",
        "trace",
        "servo",
    ];
    for name in every {
        assert!(commands.contains(name), "no corpus input parses `{name}`");
    }
    assert!(all.iter().any(|s| s.sets_accepted > 0), "no accepted set");
    assert!(all.iter().any(|s| s.sets_refused > 0), "no refused set");
    assert!(all.iter().any(|s| s.line_errors > 0), "no refused line");
    assert!(all.iter().any(|s| s.parse_errors > 0), "no parse error");
}

#[test]
fn servo_protocol_corpus_holds_and_covers_every_frame_kind() {
    let all = run_all("servo_protocol", servo::check);
    let responses: BTreeSet<&str> = all
        .iter()
        .flat_map(|s| s.responses.iter().copied())
        .collect();
    let requests: BTreeSet<&str> = all
        .iter()
        .flat_map(|s| s.requests.iter().copied())
        .collect();
    for kind in ["ping", "angle", "monitor", "read-data", "write-data"] {
        assert!(
            responses.contains(kind),
            "no corpus frame decodes as response {kind}"
        );
    }
    for kind in [
        "ping",
        "read-data",
        "write-data",
        "set-angle",
        "damping",
        "query-angle",
        "set-angle-by-interval",
        "set-angle-by-velocity",
        "query-monitor",
        "sync-set-angle",
        "sync-set-angle-by-interval",
        "sync-set-angle-by-velocity",
    ] {
        assert!(
            requests.contains(kind),
            "no corpus frame decodes as request {kind}"
        );
    }
    assert!(
        all.iter().any(|s| s.errors > 0),
        "no corrupt frame in the corpus"
    );
}

#[test]
fn settings_record_corpus_holds_and_has_a_valid_record() {
    let all = run_all("settings_record", record::check);
    assert!(all.iter().any(|s| s.accepted), "no record loads as saved");
    assert!(
        all.iter().any(|s| s.exact),
        "no record of this build's layout in the corpus"
    );
    assert!(
        all.iter().any(|s| s.accepted && !s.exact),
        "no record of an earlier layout (migrated) in the corpus"
    );
    assert!(
        all.iter().any(|s| !s.accepted && !s.accepted_with_checksum),
        "no record refused for its values"
    );
    assert!(all.iter().any(|s| s.generated_sets > 0));
}

#[test]
fn calib_csv_corpus_holds_and_has_a_realistic_file() {
    let all = run_all("calib_csv", calib::check);
    assert!(
        all.iter().any(|s| s.rows >= 100),
        "no realistic measurement file (≥ 100 rows) in the corpus"
    );
    assert!(all.iter().any(|s| s.error.is_some()), "no refused CSV");
}

#[test]
fn grbl_corpus_holds_and_covers_every_block_and_many_errors() {
    let all = run_all("grbl", grbl::check);
    let blocks: BTreeSet<&str> = all.iter().flat_map(|s| s.blocks.iter().copied()).collect();
    for kind in ["rapid", "line", "arc", "dwell", "pause", "end", "jog"] {
        assert!(
            blocks.contains(kind),
            "no corpus input yields a {kind} block"
        );
    }
    let errors: BTreeSet<u8> = all.iter().flat_map(|s| s.errors.iter().copied()).collect();
    assert!(errors.len() >= 20, "only errors {errors:?} in the corpus");
    assert!(all.iter().any(|s| s.realtime > 0), "no realtime byte");
}

#[test]
fn pelco_corpus_holds_and_covers_every_command_in_both_dialects() {
    let all = run_all("pelco", pelco::check);
    let kinds: BTreeSet<String> = all
        .iter()
        .flat_map(|s| s.commands.iter().cloned())
        .collect();
    for kind in [
        "stop",
        "move",
        "set-preset",
        "clear-preset",
        "goto-preset",
        "set-aux",
        "clear-aux",
        "remote-reset",
        "set-pan",
        "set-tilt",
        "query-pan",
        "query-tilt",
        "pan-position",
        "tilt-position",
        "other",
    ] {
        assert!(
            kinds.contains(&format!("D:{kind}")),
            "no corpus frame decodes as PELCO-D {kind}"
        );
    }
    for kind in [
        "stop",
        "move",
        "set-preset",
        "goto-preset",
        "set-pan",
        "query-pan",
    ] {
        assert!(
            kinds.contains(&format!("P:{kind}")),
            "no corpus frame decodes as PELCO-P {kind}"
        );
    }
    let bad: u32 = all.iter().map(|s| s.counters.bad_checksums).sum();
    let foreign: u32 = all.iter().map(|s| s.counters.other_addresses).sum();
    assert!(
        bad > 0 && foreign > 0,
        "the corpus has no bad or foreign frames"
    );
    // The junk property saw every kind of junk between good frames.
    let junk = all.iter().fold([0; 4], |mut sum, s| {
        for (t, n) in sum.iter_mut().zip(s.junk.junk) {
            *t += n;
        }
        sum
    });
    assert!(
        junk.iter().all(|n| *n > 0),
        "junk (garbage, wrong checksum, truncated, other address): {junk:?}"
    );
}
