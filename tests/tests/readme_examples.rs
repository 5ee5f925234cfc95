//! The README's commands run as written: every `cargo xtask sim --script
//! FILE` it shows names a file of the repository, and that file runs in
//! the simulator to the end with every line answered `ok` and the laser
//! checked by the safety checker. (`calib fit` on the README's CSV is
//! tested in xtask's calib tests.)

use std::path::{Path, PathBuf};

use laser_sim::world::SimOptions;
use system_tests::{assert_all_ok, run_checked};

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The FILE of every `--script FILE` in `text`, in order.
fn script_files(text: &str) -> Vec<String> {
    let words: Vec<&str> = text.split_whitespace().collect();
    words
        .windows(2)
        .filter(|w| w[0] == "--script")
        .map(|w| w[1].trim_end_matches(['`', ',', '.']).to_owned())
        .collect()
}

#[test]
fn script_files_are_found_in_readme_text() {
    let text =
        "run `cargo xtask sim --script a/b.txt --until-idle`.\n`cargo xtask sim --script\nc.nc`";
    assert_eq!(script_files(text), vec!["a/b.txt", "c.nc"]);
}

#[test]
fn every_readme_simulator_script_runs_as_written() {
    let readme = std::fs::read_to_string(repo_root().join("README.md")).expect("README.md");
    let files = script_files(&readme);
    assert!(
        files.len() >= 2,
        "the README shows its first commands and its G-code example as scripts: {files:?}"
    );
    for file in files {
        let path = repo_root().join(&file);
        let script = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("README names {file}, which cannot be read: {e}"));
        let report = run_checked(&script, SimOptions::default());
        assert_all_ok(&report, &file);
        assert!(
            report.transcript.lines.iter().any(|(_, l)| l == "ok"),
            "{file}: no line was answered"
        );
    }
}
