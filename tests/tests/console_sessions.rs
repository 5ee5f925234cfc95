//! The console's sessions (issue 25): what follows a soft reset in the
//! host's input belongs to the session after the reset, and a host that
//! closes the port and opens it again gets a fresh session at once.

use laser_sim::world::SimOptions;
use system_tests::{run_with, terminal_lines};

/// Index of the first transcript line equal to `line` at or after `from`.
fn position_of(lines: &[&str], from: usize, line: &str) -> usize {
    lines[from..]
        .iter()
        .position(|l| *l == line)
        .map(|i| i + from)
        .unwrap_or_else(|| panic!("{line:?} missing after line {from}: {lines:#?}"))
}

#[test]
fn an_unlock_typed_with_the_soft_reset_unlocks_after_it() {
    // `\x18$X\n` in one write: the reset (ALARM:3, it interrupted motion)
    // comes first, then `$X` unlocks, so the next G0 runs. It answered
    // `ok` to `$X` before ALARM:3 and the banner, and the G0 got error:9.
    let report = run_with(
        "G1 X20 Y0 F300\nwait 300\n@realtime 0x18\n$X\nG0 X0 Y0\n",
        SimOptions::default(),
    );
    let lines = terminal_lines(&report);
    let unlock = position_of(&lines, 0, "> $X");
    let alarm = position_of(&lines, 0, "ALARM:3");
    let banner = lines
        .iter()
        .position(|l| l.starts_with("Grbl 1.1"))
        .expect("the banner");
    let unlock_ok = position_of(&lines, unlock, "ok");
    assert!(
        alarm < unlock_ok && banner < unlock_ok,
        "the reset's lines come before the unlock's ok: {lines:#?}"
    );
    let g0 = position_of(&lines, unlock_ok, "> G0 X0 Y0");
    assert_eq!(lines.get(g0 + 1), Some(&"ok"), "{lines:#?}");
    assert!(report.idle_at_end);
}

#[test]
fn a_move_typed_with_the_soft_reset_runs_after_it() {
    // `\x18G1 X10 …` at one instant: the move belongs to the session after
    // the reset and runs (it got `ok` and was then cleared by the reset).
    let report = run_with(
        "@realtime 0x18\nG1 X10 Y0 F600\nwait 2000\n@realtime ?\nwait 10\n",
        SimOptions::default(),
    );
    let lines = terminal_lines(&report);
    let status = lines
        .iter()
        .find(|l| l.starts_with('<'))
        .expect("a status report");
    assert!(
        status.starts_with("<Idle|MPos:10.000,0.000"),
        "the move ran: {status}\n{lines:#?}"
    );
}
