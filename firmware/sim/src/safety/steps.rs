//! (d) Short task steps.

use super::violation::{MAX_STEP_NS, Violation, ViolationKind};
use crate::executor::{TaskKind, TaskSteps, recurring_steps};
use crate::world::SimReport;

/// (d) No firmware task step longer than [`MAX_STEP_NS`] of CPU time.
pub(super) fn short_steps(steps: &[TaskSteps]) -> Vec<Violation> {
    let mut found = Vec::new();
    for task in steps.iter().filter(|s| s.kind == TaskKind::Firmware) {
        for &(t_us, cpu_ns) in task.long_steps.iter().filter(|(_, ns)| *ns > MAX_STEP_NS) {
            found.push(Violation {
                kind: ViolationKind::LongStep,
                t_us,
                detail: format!(
                    "{} task step took {:.3} ms of CPU time (limit {:.3} ms)",
                    task.name,
                    cpu_ns as f64 / 1e6,
                    MAX_STEP_NS as f64 / 1e6
                ),
            });
        }
        let unlisted = task
            .long_step_count
            .saturating_sub(task.long_steps.len() as u64);
        if unlisted > 0 {
            found.push(Violation {
                kind: ViolationKind::LongStep,
                t_us: task.long_steps.last().map_or(0, |s| s.0),
                detail: format!("{} task: {unlisted} more long steps", task.name),
            });
        }
    }
    found
}

/// Runs of a simulation [`steady_steps`] makes at most.
pub const NOISE_RUNS: usize = 3;

/// Runs the simulation `run` makes and returns its report with the host's
/// load taken out of the step accounting (SPEC §9: no task step over
/// 1 ms): a firmware step counts as long only if it is long in every run
/// (same task, same simulated instant), at the least CPU time measured
/// ([`recurring_steps`]). The simulation is
/// deterministic in virtual time: a step that really is too long is long
/// in each run, while load inflates a poll now and then, never the same
/// poll three times. Runs once when no firmware step was long, else up to
/// [`NOISE_RUNS`] times (stopping when nothing recurs any more).
pub fn steady_steps(mut run: impl FnMut() -> SimReport) -> SimReport {
    let long = |steps: &[TaskSteps]| {
        steps
            .iter()
            .any(|t| t.kind == TaskKind::Firmware && t.long_step_count > 0)
    };
    let mut report = run();
    if !long(&report.task_steps) {
        return report;
    }
    let mut runs = vec![report.task_steps.clone()];
    for _ in 1..NOISE_RUNS {
        runs.push(run().task_steps);
        let kept = recurring_steps(&runs);
        let done = !long(&kept);
        let count = |steps: &[TaskSteps]| -> u64 {
            steps
                .iter()
                .filter(|t| t.kind == TaskKind::Firmware)
                .map(|t| t.long_step_count)
                .sum()
        };
        eprintln!(
            "steady_steps: run {} of {NOISE_RUNS}: {} long firmware steps in run 1, {} recur",
            runs.len(),
            runs.first().map_or(0, |r| count(r)),
            count(&kept)
        );
        report.task_steps = kept;
        if done {
            break;
        }
    }
    report
}
