//! Servo bus set-up end to end (issue 24): two servos as they ship (both
//! id 0) on one simulated bus collide; the user unplugs one, re-IDs the
//! other, plugs the first back, and then both answer a scan and `goto`
//! works. `servo zero` makes the servo's angle the axis's zero, which
//! `goto` then aims with.

use laser_sim::world::{SimOptions, SimReport};
use system_tests::{commanded_at, run_with};

/// The console lines (commands as `> …`, replies, notices) as text.
fn transcript(report: &SimReport) -> Vec<String> {
    report
        .transcript
        .lines
        .iter()
        .map(|(_, l)| l.clone())
        .collect()
}

/// The reply lines of the command typed as `command` (its data lines and
/// closer).
fn reply_of(lines: &[String], command: &str, nth: usize) -> Vec<String> {
    let typed = format!("> {command}");
    let start = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| **l == typed)
        .nth(nth)
        .map(|(i, _)| i + 1)
        .unwrap_or_else(|| panic!("{typed:?} #{nth} not in {lines:#?}"));
    let mut reply = Vec::new();
    for line in &lines[start..] {
        if line.starts_with('[') {
            continue;
        }
        reply.push(line.clone());
        if line == "ok" || line.starts_with("error") {
            break;
        }
    }
    reply
}

const DUPLICATE_IDS_SCRIPT: &str = "\
servo scan
servo id 0 1 confirm
@unplug-servo 1
servo scan
servo id 0 1
servo id 0 1 confirm
@plug-servo 1
servo scan
goto 5 3
wait 1500
status
";

#[test]
fn a_duplicate_id_is_found_re_ided_with_one_servo_unplugged_and_then_both_work() {
    let report = run_with(
        DUPLICATE_IDS_SCRIPT,
        SimOptions {
            servo_ids: Some(vec![0, 0]),
            ..SimOptions::default()
        },
    );
    let lines = transcript(&report);
    assert!(report.transcript.script_done, "{lines:#?}");
    assert_eq!(
        reply_of(&lines, "servo scan", 0),
        [
            "servo 0: garbled answers, more than one servo has this id",
            "0 ids answering, 1 with colliding answers",
            "ok"
        ]
    );
    assert_eq!(
        reply_of(&lines, "servo id 0 1 confirm", 0),
        [
            "servo 0: garbled answers, more than one servo has this id",
            "error: 0 ids answer and 1 collide: connect only the servo to re-ID"
        ]
    );
    assert_eq!(
        reply_of(&lines, "servo scan", 1),
        [
            "servo 0: 0.0 deg, 7.40 V, 30 C",
            "1 ids answering, 0 with colliding answers",
            "ok"
        ]
    );
    let dry_run = reply_of(&lines, "servo id 0 1", 0);
    assert_eq!(dry_run.len(), 2, "{dry_run:?}");
    assert!(dry_run[0].contains("repeat with confirm"), "{dry_run:?}");
    assert_eq!(
        reply_of(&lines, "servo id 0 1 confirm", 1),
        [
            "servo 0: 0.0 deg, 7.40 V, 30 C",
            "servo 1: 0.0 deg, 7.40 V, 30 C",
            "servo 0 now answers as 1 (stored in the servo)",
            "ok"
        ]
    );
    assert_eq!(
        reply_of(&lines, "servo scan", 2),
        [
            "servo 0: 0.0 deg, 7.40 V, 30 C",
            "servo 1: 0.0 deg, 7.40 V, 30 C",
            "2 ids answering, 0 with colliding answers",
            "ok"
        ]
    );
    assert_eq!(reply_of(&lines, "goto 5 3", 0), ["ok"]);
    let status = reply_of(&lines, "status", 0).join("\n");
    assert!(status.contains("holding"), "{status}");
    // The spot is where the goto aimed (both servos moved and arrived).
    let spot = report.recording.spot.last().expect("a spot");
    assert!(
        (spot.x_cm - 5.0).abs() < 0.2 && (spot.y_cm - 3.0).abs() < 0.2,
        "spot at ({}, {})",
        spot.x_cm,
        spot.y_cm
    );
}

#[test]
fn servo_zero_sets_the_axis_zero_that_goto_aims_with() {
    let report = run_with(
        "goto 6 0\nwait 1500\nservo zero 0\nstop\nservo zero 0\ngoto 0 0\nwait 1500\nstop\nservo zero 7\nget yaw.zero_deg\n",
        SimOptions::default(),
    );
    let lines = transcript(&report);
    // Holding a goto is running: refused until `stop`.
    assert_eq!(
        reply_of(&lines, "servo zero 0", 0),
        ["error: stop the running pattern, goto or G-code before servo set-up"]
    );
    let zero = reply_of(&lines, "servo zero 0", 1);
    assert_eq!(zero.len(), 2, "{zero:?}");
    assert_eq!(zero[1], "ok");
    // `yaw.zero_deg = 13.5 (servo 0 stands there); save to keep it`
    let deg: f64 = zero[0]
        .strip_prefix("yaw.zero_deg = ")
        .and_then(|r| r.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{zero:?}"));
    assert!(deg.abs() > 1.0, "goto 6 0 turned the yaw servo: {deg}");
    // `goto 0 0` is joint zero: the yaw servo is sent to the new zero.
    let yaw_target = commanded_at(&report, u64::MAX)
        .into_iter()
        .find(|(id, _)| *id == 0)
        .map(|(_, t)| t);
    assert_eq!(yaw_target, Some((deg * 10.0).round() as i16));
    assert_eq!(
        reply_of(&lines, "servo zero 7", 0),
        ["error: servo 7 is neither yaw.id nor pitch.id"]
    );
    let get = reply_of(&lines, "get yaw.zero_deg", 0);
    assert!(get[0].contains(&format!("{deg}")), "{get:?} vs {deg}");
}

#[test]
fn servo_set_up_is_refused_while_a_pattern_runs() {
    let report = run_with(
        "pattern corner\nwait 200\nservo scan\nstop\n",
        SimOptions::default(),
    );
    let lines = transcript(&report);
    assert_eq!(
        reply_of(&lines, "servo scan", 0),
        ["error: stop the running pattern, goto or G-code before servo set-up"]
    );
}
