//! Shared helpers for the integration tests in `tests/tests/`: run a script
//! through the simulator and read what happened.

use laser_sim::safety::{Violation, ViolationKind, check, report_text};
use laser_sim::script::parse_script;
use laser_sim::world::{SimOptions, SimReport, run};

/// Runs `script` to idle in virtual time with default options.
pub fn run_to_idle(script: &str) -> SimReport {
    run_with(script, SimOptions::default())
}

/// Runs `script` to idle with the given options (script and until-idle set
/// here).
pub fn run_with(script: &str, options: SimOptions) -> SimReport {
    let steps = parse_script(script).expect("test script parses");
    run(SimOptions {
        script: steps,
        until_idle: true,
        ..options
    })
}

/// Runs `script` to idle with `options` under the safety checker: panics
/// listing every violated invariant (`laser_sim::safety`).
pub fn run_checked(script: &str, options: SimOptions) -> SimReport {
    let report = run_with(script, options);
    assert_safe(&report);
    report
}

/// Panics listing every safety violation of a finished run.
pub fn assert_safe(report: &SimReport) {
    let violations = check(report);
    assert!(violations.is_empty(), "{}", report_text(&violations));
}

/// The safety violations of `kind` in a finished run.
pub fn violations_of(report: &SimReport, kind: ViolationKind) -> Vec<Violation> {
    check(report)
        .into_iter()
        .filter(|v| v.kind == kind)
        .collect()
}

/// Every line of the terminal transcript (`> command` for what was sent).
pub fn terminal_lines(report: &SimReport) -> Vec<&str> {
    report
        .transcript
        .lines
        .iter()
        .map(|(_, l)| l.as_str())
        .collect()
}

/// Simulated time at which the terminal sent `line`, µs.
pub fn sent_at(report: &SimReport, line: &str) -> u64 {
    report
        .transcript
        .lines
        .iter()
        .find(|(_, l)| l.strip_prefix("> ") == Some(line))
        .map(|(t, _)| *t)
        .unwrap_or_else(|| panic!("{line:?} was not sent"))
}

/// Grid indices of SPEC §4.6's patterns, written out from the spec (not
/// from the firmware's pattern code).
pub mod spec_patterns {
    /// corner: (−6, 4) → (6, 4) → (6, −4) → (−6, −4).
    pub fn corner() -> Vec<(i8, i8)> {
        vec![(-6, 4), (6, 4), (6, -4), (-6, -4)]
    }
    /// horizontal: xi = −6..6 at yi = 0.
    pub fn horizontal() -> Vec<(i8, i8)> {
        (-6..=6).map(|x| (x, 0)).collect()
    }
    /// vertical: yi = 4..−4 at xi = 0.
    pub fn vertical() -> Vec<(i8, i8)> {
        (-4..=4).rev().map(|y| (0, y)).collect()
    }
    /// visit-all: yi = 2..−2, xi = −3..3, row by row.
    pub fn visit_all() -> Vec<(i8, i8)> {
        (-2..=2)
            .rev()
            .flat_map(|y| (-3..=3).map(move |x| (x, y)))
            .collect()
    }
    /// Full grid, raster: rows top to bottom, each left to right.
    pub fn raster() -> Vec<(i8, i8)> {
        (-4..=4)
            .rev()
            .flat_map(|y| (-6..=6).map(move |x| (x, y)))
            .collect()
    }
    /// Full grid, serpentine: like raster with every second row reversed.
    pub fn serpentine() -> Vec<(i8, i8)> {
        (-4..=4)
            .rev()
            .enumerate()
            .flat_map(|(row, y)| {
                let xs: Vec<i8> = if row % 2 == 0 {
                    (-6..=6).collect()
                } else {
                    (-6..=6).rev().collect()
                };
                xs.into_iter().map(move |x| (x, y))
            })
            .collect()
    }
}
