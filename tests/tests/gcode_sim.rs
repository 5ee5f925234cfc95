//! G-code through the simulated console: grbl replies, the queue, and what
//! the gimbal and the galvo draw.

use laser_sim::world::SimOptions;
use system_tests::{run_with, terminal_lines};

#[test]
fn probe_transcript() {
    let script = "$I\nG21 G90\nG0 X-20 Y-20\nM3 S1000\nG1 X20 Y-20 F1200\nG1 X20 Y20\nG2 X-20 Y20 I-20 J0\nG1 X-20 Y-20\nM5\nG0 X0 Y0\nM2\n";
    let report = run_with(script, SimOptions::default());
    for l in terminal_lines(&report) {
        eprintln!("{l}");
    }
    let lit: Vec<_> = report.recording.spot.iter().filter(|s| s.laser).collect();
    eprintln!(
        "lit samples {} of {}",
        lit.len(),
        report.recording.spot.len()
    );
    for s in lit.iter().step_by(20) {
        eprintln!("{:.3} {:.3}", s.x_cm, s.y_cm);
    }
    eprintln!(
        "end {:?} at {} us, idle {}",
        report.end, report.end_time_us, report.idle_at_end
    );
}
