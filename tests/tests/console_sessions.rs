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

/// Lines of the transcript after the last `@open`.
fn after_reopen(lines: &[(u64, String)]) -> &[(u64, String)] {
    let open = lines
        .iter()
        .rposition(|(_, l)| l == "@open")
        .expect("the port was opened again");
    &lines[open + 1..]
}

#[test]
fn a_host_that_flooded_closed_and_opened_the_port_again_is_answered_at_once() {
    // Issue 25, defect 8: a host typed far more than it read, stopped
    // reading, closed the port and opened it again: `stop` and `version`
    // were not answered within 15 s. A new connection is a new session:
    // the old one's input and replies are gone, the new lines answered.
    for flood in ["version", "params", "$G", "G1 X1 Y1 F6000"] {
        let mut script = String::from("@stall-read 60000\n");
        for _ in 0..400 {
            script += &format!("@type-ahead {flood}\n");
        }
        script += "wait 1000\n@close\nwait 200\n@open\nstop\nversion\nwait 500\n";
        let report = run_with(&script, SimOptions::default());
        assert!(report.transcript.script_done, "{flood}");
        let lines = after_reopen(&report.transcript.lines);
        let texts: Vec<&str> = lines.iter().map(|(_, l)| l.as_str()).collect();
        assert_eq!(texts.first(), Some(&"> stop"), "{flood}: {texts:#?}");
        assert_eq!(texts.get(1), Some(&"ok"), "{flood}: {texts:#?}");
        assert_eq!(texts.get(2), Some(&"> version"), "{flood}: {texts:#?}");
        assert!(
            texts.get(3).is_some_and(|l| l.starts_with("laser-pointer")),
            "{flood}: {texts:#?}"
        );
        assert_eq!(texts.get(4), Some(&"ok"), "{flood}: {texts:#?}");
        let opened_at = lines[0].0;
        let answered_at = lines[4].0;
        assert!(
            answered_at - opened_at < 1_000_000,
            "{flood}: answered {} µs after the port opened",
            answered_at - opened_at
        );
    }
}

#[test]
fn a_job_line_waiting_for_room_when_the_host_left_is_stopped_for_the_next_host() {
    // The last host left a G-code line waiting for room in the motion
    // queue (its `ok` would come only when a block ends): the new host
    // is answered at once, and the old job does not run on unattended.
    let mut script = String::from("M3 S1000\n");
    for i in 0..20 {
        script += &format!("@type-ahead G1 X{} Y0 F60\n", i % 2 * 10);
    }
    script += "wait 500\n@close\nwait 100\n@open\nversion\n@realtime ?\nwait 100\n";
    let report = run_with(&script, SimOptions::default());
    let lines = after_reopen(&report.transcript.lines);
    let texts: Vec<&str> = lines.iter().map(|(_, l)| l.as_str()).collect();
    assert_eq!(texts.first(), Some(&"> version"), "{texts:#?}");
    assert!(
        texts.get(1).is_some_and(|l| l.starts_with("laser-pointer")),
        "{texts:#?}"
    );
    assert_eq!(texts.get(2), Some(&"ok"), "{texts:#?}");
    assert!(lines[2].0 - lines[0].0 < 1_000_000, "{texts:#?}");
    let status = texts
        .iter()
        .find(|l| l.starts_with('<'))
        .expect("a status report");
    assert!(
        status.starts_with("<Idle|"),
        "the old job stopped: {status}"
    );
    assert!(report.idle_at_end);
}
