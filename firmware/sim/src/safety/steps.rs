//! (d) Short task steps.

use super::{MAX_STEP_NS, Violation, ViolationKind};
use crate::executor::{TaskKind, TaskSteps};
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
