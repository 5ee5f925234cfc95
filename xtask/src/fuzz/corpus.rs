//! The committed corpus: minimised after each run with libFuzzer's merge.

use std::path::Path;

use anyhow::{Context, Result, bail};

use super::libfuzzer::{MAX_INPUT_LEN, run_fuzzer};

/// Replaces the committed corpus with its seeds (`seed-*`, kept always),
/// the other corpus files that reach edges the seeds do not, and the new
/// `found` inputs that reach edges none of those do (libFuzzer's merge,
/// edges only: hit counts would keep hundreds of near-duplicates).
/// Returns the new corpus's file names.
pub(super) fn minimise_corpus(
    target: &str,
    corpus: &Path,
    found: &Path,
    work: &Path,
) -> Result<Vec<String>> {
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
pub(super) fn list_files(dir: &Path) -> Vec<String> {
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
