extern crate std;
use std::format;
use std::string::String;

use super::*;

fn drain(out: &Outbound) -> heapless::Vec<OutLine, 256> {
    let mut lines = heapless::Vec::new();
    while let Some(line) = out.take() {
        let _ = lines.push(line);
    }
    lines
}

#[test]
fn lines_come_out_whole_and_in_order() {
    let out = Outbound::new();
    assert!(out.push(LineKind::Notice, "info: servo 1 answering again"));
    assert!(out.push(LineKind::Data, "dwell_ms = 1000 ms"));
    assert!(out.push(LineKind::Ok, ""));
    let lines = drain(&out);
    let kinds: heapless::Vec<LineKind, 8> = lines.iter().map(|l| l.kind).collect();
    assert_eq!(
        kinds.as_slice(),
        [LineKind::Notice, LineKind::Data, LineKind::Ok]
    );
    assert_eq!(lines[1].text.as_str(), "dwell_ms = 1000 ms");
    assert_eq!(out.queued_bytes(), 0);
}

#[test]
fn a_full_queue_drops_whole_data_lines_keeps_notices_and_the_closer_and_says_where() {
    let out = Outbound::new();
    out.begin_command();
    let line = String::from("x").repeat(100);
    let mut queued = 0;
    for _ in 0..200 {
        if out.push(LineKind::Data, &line) {
            queued += 1;
        }
    }
    assert!(queued > 0 && queued < 200);
    assert!(out.queued_bytes() <= DATA_LIMIT);
    assert!(out.push(LineKind::Notice, "error: servo 1 fault (Timeout)"));
    assert!(out.push(LineKind::Ok, ""));
    assert!(!out.awaiting_close());
    let lines = drain(&out);
    assert_eq!(lines.len(), queued + 3);
    assert!(lines[..queued].iter().all(|l| l.text.as_str() == line));
    let report = &lines[queued];
    assert_eq!(report.kind, LineKind::Notice);
    assert_eq!(
        report.text.as_str(),
        format!(
            "info: {} reply lines dropped while the host was not reading",
            200 - queued
        )
    );
    assert_eq!(lines[queued + 1].kind, LineKind::Notice);
    assert_eq!(lines[queued + 2].kind, LineKind::Ok);
    assert!(out.unreported_drops().is_empty());
}

#[test]
fn notices_fill_only_their_share_and_drops_at_the_end_are_reported_when_empty() {
    let out = Outbound::new();
    let notice = String::from("e").repeat(REPLY_LINE_LEN);
    let mut dropped = 0;
    for _ in 0..100 {
        if !out.push(LineKind::Notice, &notice) {
            dropped += 1;
        }
    }
    assert!(dropped > 0);
    assert!(out.has_closer_room(), "a closer always fits");
    assert!(out.push(LineKind::Error, "unknown command"));
    let lines = drain(&out);
    let report = &lines[lines.len() - 2];
    assert!(
        report
            .text
            .starts_with(&format!("error: {dropped} notices dropped")),
        "{report:?}"
    );
    assert_eq!(lines[lines.len() - 1].kind, LineKind::Error);
    // Drops after the last queued line are reported once it is empty.
    for _ in 0..100 {
        out.push(LineKind::Notice, &notice);
    }
    out.push(LineKind::Data, "lost");
    let lines = drain(&out);
    let last = lines.last().map(|l| l.text.as_str()).unwrap_or("");
    assert!(last.contains("and 1 reply line dropped"), "{last}");
    assert!(out.take().is_none());
}

#[test]
fn long_text_is_cut_on_a_character_boundary() {
    let out = Outbound::new();
    let text = String::from("é").repeat(REPLY_LINE_LEN);
    assert!(out.push(LineKind::Data, &text));
    let line = out.take().expect("queued");
    assert_eq!(line.text.len(), REPLY_LINE_LEN);
    assert!(line.text.chars().all(|c| c == 'é'));
}

#[test]
fn the_longest_reply_fits_a_reading_host() {
    use crate::settings::{PARAMS, ParamLine, Settings};
    let out = Outbound::new();
    let settings = Settings::default();
    for param in PARAMS {
        assert!(out.push_fmt(
            LineKind::Data,
            format_args!("{}", ParamLine(param, settings.get(param)))
        ));
    }
    assert!(out.queued_bytes() * 3 / 2 < DATA_LIMIT, "room to spare");
}

#[test]
fn a_new_session_drops_the_last_ones_replies_but_not_its_notices() {
    // Issue 25, defect 8: a host that stopped reading, closed the port and
    // opened it again read the old session's replies first (and its
    // commands waited behind them).
    let out = Outbound::new();
    let line = String::from("d").repeat(100);
    for _ in 0..200 {
        out.push(LineKind::Data, &line);
    }
    assert!(out.push(LineKind::Notice, "error: servo 1 fault (Timeout)"));
    out.push(LineKind::Ok, "");
    out.begin_command();
    out.push(LineKind::Data, "old reply data");
    assert!(out.new_session(), "a command was in flight");
    // Its reply goes to no one; a notice meanwhile does.
    out.push(LineKind::Data, "old reply data 2");
    out.push(LineKind::Notice, "info: servo 1 answering again");
    out.push(LineKind::Ok, "");
    assert!(!out.awaiting_close());
    // The new session's command is answered.
    out.begin_command();
    out.push(LineKind::Data, "new");
    out.push(LineKind::Ok, "");
    let lines = drain(&out);
    let texts: heapless::Vec<&str, 8> = lines.iter().map(|l| l.text.as_str()).collect();
    assert_eq!(
        texts.as_slice(),
        [
            "error: servo 1 fault (Timeout)",
            "info: servo 1 answering again",
            "new",
            ""
        ]
    );
    assert!(out.unreported_drops().is_empty());
    assert!(!out.new_session(), "nothing in flight");
}

#[test]
fn lines_taken_count_what_the_writer_took() {
    let out = Outbound::new();
    let before = out.lines_taken();
    out.push(LineKind::Data, "a");
    out.push(LineKind::Ok, "");
    assert_eq!(out.lines_taken(), before);
    drain(&out);
    assert_eq!(out.lines_taken(), before.wrapping_add(2));
}

#[test]
fn a_quiet_command_reply_is_kept_from_the_host_but_notices_are_not() {
    let out = Outbound::new();
    assert!(out.begin_quiet_command());
    // One command at a time: neither a second quiet one nor the console's.
    assert!(!out.begin_quiet_command());
    assert!(out.awaiting_close());
    assert!(out.push(LineKind::Data, "oq_cm = 100  # gimbal"));
    assert!(out.push(LineKind::Notice, "servo 1 not answering"));
    assert!(out.take_quiet_reply().is_none(), "not closed yet");
    assert!(out.push(LineKind::Ok, ""));
    assert!(!out.awaiting_close());
    let reply = out.take_quiet_reply().expect("closed");
    assert_eq!(reply.data.as_str(), "oq_cm = 100  # gimbal");
    assert_eq!(reply.closed, Some(true));
    assert!(out.take_quiet_reply().is_none(), "taken once");
    let lines = drain(&out);
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0].kind, LineKind::Notice);
    // The console's next command replies to the host as before.
    out.begin_command();
    assert!(out.push(LineKind::Error, "bad"));
    assert_eq!(drain(&out).len(), 1);
    assert!(out.take_quiet_reply().is_none());
}

#[test]
fn a_direct_line_neither_closes_nor_answers_the_quiet_command_in_flight() {
    let out = Outbound::new();
    assert!(out.begin_quiet_command());
    // The console refuses a line it parsed and a `?` is answered meanwhile.
    assert!(out.push_from(Origin::Direct, LineKind::Error, "unknown command 'xyzzy'"));
    assert!(out.push_from(
        Origin::Direct,
        LineKind::Data,
        "<Idle|MPos:0.000,0.000,0.000>"
    ));
    assert!(out.awaiting_close(), "the quiet command is still in flight");
    assert!(out.take_quiet_reply().is_none());
    assert!(out.push(LineKind::Data, "pelco.baud = 9600"));
    assert!(out.push(LineKind::Ok, ""));
    let reply = out.take_quiet_reply().expect("closed");
    assert_eq!(reply.data.as_str(), "pelco.baud = 9600");
    let host = drain(&out);
    assert_eq!(host.len(), 2);
    assert_eq!(
        (host[0].kind, host[1].kind),
        (LineKind::Error, LineKind::Data)
    );
}
