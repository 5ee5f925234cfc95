//! A host that stops reading its replies (issue 9, defect 4): the fault
//! shutdown is not delayed by it, no line reaches the host cut or glued,
//! every line typed gets exactly one closing reply in order, and replies
//! dropped meanwhile are counted and reported once the host reads again.

use std::collections::HashMap;
use std::sync::OnceLock;

use laser_sim::servo_port::{BusFaults, SilentWindow};
use laser_sim::world::{SimOptions, SimReport};
use proptest::prelude::*;
use system_tests::console::{ExpectedReply, ReplyAudit, audit_replies, replies_of};
use system_tests::{gimbal_dark_after, run_with, sent_at};

/// Commands whose reply depends neither on time nor on what ran before,
/// and that change nothing the sequencer does (no parameter, no motion).
const COMMANDS: &[&str] = &[
    "params",
    "help",
    "version",
    "get dwell_ms",
    "get grid.pitch_cm",
    "bogus",
    "set dwell_ms -5",
    "get nosuch",
    "laser auto",
];

/// Each command's reply from a host that reads.
fn expected() -> &'static HashMap<String, ExpectedReply> {
    static EXPECTED: OnceLock<HashMap<String, ExpectedReply>> = OnceLock::new();
    EXPECTED.get_or_init(|| {
        let mut replies = replies_of(COMMANDS);
        replies.insert(
            "pattern visit-all".to_owned(),
            ExpectedReply {
                data: Vec::new(),
                closer: "ok".to_owned(),
            },
        );
        replies.insert(
            "stop".to_owned(),
            ExpectedReply {
                data: Vec::new(),
                closer: "ok".to_owned(),
            },
        );
        replies
    })
}

/// Servo 1 goes silent for good at `fault_ms`.
fn silent_servo_at(fault_ms: u64) -> SimOptions {
    SimOptions {
        faults: BusFaults {
            silent: vec![SilentWindow {
                id: 1,
                from_ms: fault_ms,
                until_ms: None,
            }],
            ..BusFaults::default()
        },
        ..SimOptions::default()
    }
}

/// Time from `t_us` (laser on just before) to the next laser-off, µs.
fn dark_after(report: &SimReport, t_us: u64) -> u64 {
    assert!(
        report.recording.laser_at(t_us - 1),
        "the laser was on at {t_us} µs"
    );
    gimbal_dark_after(report, t_us)
}

fn audit(report: &SimReport) -> ReplyAudit {
    audit_replies(report, expected()).unwrap_or_else(|e| {
        let lines: Vec<_> = report.transcript.lines.iter().map(|(_, l)| l).collect();
        panic!("{e}\ntranscript: {lines:#?}")
    })
}

fn fault_was_told(audit: &ReplyAudit) -> bool {
    audit
        .notices
        .iter()
        .any(|(_, n)| n.starts_with("[error: servo 1 fault"))
        || audit.dropped_notices_reported > 0
}

#[test]
fn a_host_that_stops_reading_delays_no_fault_shutdown_and_gets_whole_replies() {
    // Four `params` (54 lines each) typed while the host reads nothing for
    // 3 s; servo 1 goes silent 20 ms into the stall.
    let script = "pattern visit-all\nwait 1000\n@stall-read 3000\n\
                  @type-ahead params\n@type-ahead params\n@type-ahead params\nparams\n\
                  get dwell_ms\nbogus\nversion\nwait 300\n";
    let report = run_with(script, silent_servo_at(1020));
    let dark_us = dark_after(&report, 1_020_000);
    let quiet = run_with("pattern visit-all\nwait 2000\n", silent_servo_at(1020));
    let quiet_dark_us = dark_after(&quiet, 1_020_000);
    eprintln!(
        "silent servo -> laser off: {dark_us} µs during a host stall, \
         {quiet_dark_us} µs with a host that reads"
    );
    assert!(dark_us < 200_000, "laser off {dark_us} µs after the fault");
    assert!(dark_us <= quiet_dark_us, "the stall delayed the shutdown");

    let audit = audit(&report);
    assert!(
        audit.dropped_lines_reported > 0,
        "the stall was long enough to drop lines: {audit:?}"
    );
    assert!(
        audit
            .notices
            .iter()
            .any(|(_, n)| n.starts_with("[error: servo 1 fault")),
        "the fault notice reached the host: {:?}",
        audit.notices
    );
    // Reported when the host reads again, not before.
    let first_drop_report = audit
        .notices
        .iter()
        .find(|(_, n)| n.contains("dropped while the host was not reading"))
        .map(|(t, _)| *t)
        .expect("a drop report");
    assert!(first_drop_report >= 4_000_000, "{first_drop_report} µs");
    assert!(report.idle_at_end, "the fault stopped the pattern");
}

#[test]
fn stop_typed_while_the_host_is_not_reading_still_stops_at_once() {
    let script = "pattern visit-all\nwait 1000\n@stall-read 3000\n\
                  @type-ahead params\n@type-ahead params\nwait 400\nstop\nwait 300\n";
    let report = run_with(script, SimOptions::default());
    let stop_at = sent_at(&report, "stop");
    let dark_us = dark_after(&report, stop_at);
    assert!(dark_us < 5_000, "laser off {dark_us} µs after stop");
    audit(&report);
    assert!(report.idle_at_end);
}

/// One stall: when it starts after the previous step, how long it lasts,
/// the lines typed ahead during it and the line typed last (its reply is
/// awaited, so the host reads again before going on).
#[derive(Debug, Clone)]
struct Stall {
    after_ms: u64,
    length_ms: u64,
    typed_ahead: Vec<&'static str>,
    last: &'static str,
}

fn command() -> impl Strategy<Value = &'static str> {
    proptest::sample::select(COMMANDS)
}

fn stall() -> impl Strategy<Value = Stall> {
    (
        0u64..1500,
        100u64..4000,
        proptest::collection::vec(command(), 0..6),
        command(),
    )
        .prop_map(|(after_ms, length_ms, typed_ahead, last)| Stall {
            after_ms,
            length_ms,
            typed_ahead,
            last,
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random stalls (start, length, lines typed meanwhile) with a servo
    /// fault during the first one: the laser goes off exactly as soon
    /// after the fault as without any stall or command (the console delays
    /// nothing), whole lines, one closer per line in order, drops accounted
    /// for and the fault told; afterwards every command is answered in
    /// full.
    #[test]
    fn random_host_stalls_keep_the_protocol_and_the_fault_shutdown(
        stalls in proptest::collection::vec(stall(), 1..4),
        fault_into_first_stall in 0.0f64..1.0,
        after in proptest::collection::vec(command(), 1..4),
    ) {
        let mut script = String::from("pattern visit-all\nwait 500\n");
        let mut t_ms = 500;
        let mut fault_ms = 0;
        for (i, s) in stalls.iter().enumerate() {
            script += &format!("wait {}\n@stall-read {}\n", s.after_ms, s.length_ms);
            t_ms += s.after_ms;
            if i == 0 {
                fault_ms = t_ms + (fault_into_first_stall * s.length_ms as f64) as u64;
            }
            for line in &s.typed_ahead {
                script += &format!("@type-ahead {line}\n");
            }
            script += &format!("{}\n", s.last);
            // The last line's reply comes once the stall ends.
            t_ms += s.length_ms;
        }
        for line in &after {
            script += &format!("{line}\n");
        }
        script += "wait 300\n";
        let report = run_with(&script, silent_servo_at(fault_ms));

        let dark_us = dark_after(&report, fault_ms * 1000);
        let quiet = run_with(
            &format!("pattern visit-all\nwait {}\n", fault_ms + 1000),
            silent_servo_at(fault_ms),
        );
        let quiet_dark_us = dark_after(&quiet, fault_ms * 1000);
        prop_assert!(
            dark_us <= quiet_dark_us,
            "laser off {} µs after the fault, {} µs with a host that reads",
            dark_us,
            quiet_dark_us
        );
        let audit = audit(&report);
        prop_assert!(fault_was_told(&audit), "fault neither told nor counted: {:?}", audit.notices);
        // Once the host reads again nothing more is dropped: the commands
        // typed after the last stall are answered in full.
        let tail: usize = after.iter().map(|c| expected()[*c].data.len()).sum();
        let typed_before_tail = 1 + stalls.iter().map(|s| s.typed_ahead.len() + 1).sum::<usize>();
        let lines = &report.transcript.lines;
        let tail_start = lines
            .iter()
            .enumerate()
            .filter(|(_, (_, l))| l.starts_with("> "))
            .nth(typed_before_tail)
            .map(|(i, _)| i)
            .expect("the tail was typed");
        let tail_received = lines[tail_start..]
            .iter()
            .filter(|(_, l)| !(l.starts_with('[') || l.starts_with("> ") || l == "ok" || l.starts_with("error:")))
            .count();
        prop_assert_eq!(tail_received, tail);
    }
}

#[test]
fn a_host_that_reads_gets_every_line_even_when_it_types_ahead() {
    // Pasting several commands at once: nothing dropped, all in order.
    let script = "pattern visit-all\nwait 500\n@type-ahead help\n@type-ahead params\n\
                  @type-ahead bogus\n@type-ahead params\nversion\nwait 100\n";
    let report = run_with(script, SimOptions::default());
    let audit = audit(&report);
    assert_eq!(audit.dropped_lines_reported, 0, "{:?}", audit.notices);
    assert_eq!(audit.data_lines, audit.data_lines_expected);
    assert!(audit.data_lines > 100);
}

#[test]
fn a_host_that_reads_with_short_pauses_gets_every_typed_ahead_line_run() {
    // Issue 25, defect 7: a host that reads (here with a 150 ms pause,
    // shorter than `usb::HOST_STALL`) typing ahead more than the reply
    // queue holds had most lines refused as "not reading". Its input must
    // wait instead (back-pressure), and every line run.
    for (line, data) in [("version", "laser-pointer"), ("$G", "[GC:")] {
        let mut script = String::from("@stall-read 150\n");
        for _ in 0..600 {
            script += &format!("@type-ahead {line}\n");
        }
        script += "wait 2000\n";
        let report = run_with(&script, SimOptions::default());
        assert!(report.transcript.script_done);
        let lines = &report.transcript.lines;
        let refused = lines.iter().filter(|(_, l)| l.contains("not run")).count();
        let closers = lines.iter().filter(|(_, l)| l == "ok").count();
        let answers = lines.iter().filter(|(_, l)| l.starts_with(data)).count();
        assert_eq!(refused, 0, "{line}: lines refused to a host that reads");
        assert_eq!((closers, answers), (600, 600), "{line}");
        let dropped = report
            .transcript
            .notices
            .iter()
            .filter(|(_, n)| n.contains("dropped"));
        assert_eq!(dropped.count(), 0, "{line}: replies dropped");
    }
}
