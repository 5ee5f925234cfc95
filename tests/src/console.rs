//! Checks of the console protocol as a host sees it: whole lines, replies
//! in order, exactly one closer per line, dropped lines accounted for.

use std::collections::HashMap;

use laser_sim::world::SimReport;

/// What a command answers when the host reads: its data lines, then
/// its closer (`ok` or `error: …`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExpectedReply {
    /// Data lines, in order.
    pub data: Vec<String>,
    /// The closing line.
    pub closer: String,
}

/// Runs each of `commands` once, in order, on an idle simulator whose
/// host reads everything: each command's reply. Use commands whose
/// reply does not depend on time or on what ran before.
pub fn replies_of(commands: &[&str]) -> HashMap<String, ExpectedReply> {
    let script: String = commands.iter().map(|c| format!("{c}\n")).collect();
    let report = super::run_to_idle(&script);
    let mut replies = HashMap::new();
    let mut current: Option<(String, Vec<String>)> = None;
    for (_, line) in &report.transcript.lines {
        if let Some(sent) = line.strip_prefix("> ") {
            current = Some((sent.to_owned(), Vec::new()));
        } else if line.starts_with('[') {
            continue;
        } else if let Some((sent, data)) = current.as_mut() {
            if line == "ok" || line.starts_with("error:") {
                replies.insert(
                    sent.clone(),
                    ExpectedReply {
                        data: std::mem::take(data),
                        closer: line.clone(),
                    },
                );
            } else {
                data.push(line.clone());
            }
        }
    }
    for c in commands {
        assert!(replies.contains_key(*c), "no reply to {c:?}");
    }
    replies
}

/// What a run's host received, audited.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct ReplyAudit {
    /// Lines typed.
    pub sent: usize,
    /// Data lines received.
    pub data_lines: usize,
    /// Data lines expected from the commands typed.
    pub data_lines_expected: usize,
    /// Reply lines the device reported dropped.
    pub dropped_lines_reported: usize,
    /// Notices the device reported dropped.
    pub dropped_notices_reported: usize,
    /// Notices received (drop reports included), with their time, µs.
    pub notices: Vec<(u64, String)>,
}

/// Reply lines and notices a drop report (`[info: 3 reply lines
/// dropped while the host was not reading]`, `[error: 1 notice and 2
/// reply lines dropped …]`) counts; `None` for other lines.
pub fn dropped_counts(line: &str) -> Option<(usize, usize)> {
    if !(line.starts_with('[') && line.contains(" dropped while the host was not reading")) {
        return None;
    }
    let words: Vec<&str> = line.split_whitespace().collect();
    let (mut lines, mut notices) = (0, 0);
    for pair in words.windows(2) {
        let Ok(n) = pair[0].parse::<usize>() else {
            continue;
        };
        if pair[1].starts_with("reply") {
            lines = n;
        } else if pair[1].starts_with("notice") {
            notices = n;
        }
    }
    Some((lines, notices))
}

/// Checks what the host received against `expected` (the reply of
/// every line typed): no line cut or glued (each is `ok`, `error: …`,
/// a `[…]` notice, or a data line of the reply in progress, in order),
/// exactly one closer per line typed, in order and as expected, and
/// every data line either received or reported dropped.
pub fn audit_replies(
    report: &SimReport,
    expected: &HashMap<String, ExpectedReply>,
) -> Result<ReplyAudit, String> {
    let transcript = &report.transcript;
    if !transcript.unterminated.is_empty() {
        return Err(format!("unterminated line {:?}", transcript.unterminated));
    }
    let mut sent = Vec::new();
    let mut received = Vec::new();
    for (t, line) in &transcript.lines {
        match line.strip_prefix("> ") {
            Some(s) => sent.push(s),
            None => received.push((*t, line.as_str())),
        }
    }
    let mut audit = ReplyAudit {
        sent: sent.len(),
        ..ReplyAudit::default()
    };
    for s in &sent {
        let reply = expected
            .get(*s)
            .ok_or(format!("no expected reply for {s:?}"))?;
        audit.data_lines_expected += reply.data.len();
    }
    let (mut reply_index, mut cursor) = (0usize, 0usize);
    for (t, line) in received {
        if line.starts_with('[') {
            if !line.ends_with(']') {
                return Err(format!("notice cut or glued: {line:?}"));
            }
            if let Some((lines, notices)) = dropped_counts(line) {
                audit.dropped_lines_reported += lines;
                audit.dropped_notices_reported += notices;
            }
            audit.notices.push((t, line.to_owned()));
            continue;
        }
        let Some(command) = sent.get(reply_index) else {
            return Err(format!("{line:?} after every line typed was answered"));
        };
        let reply = &expected[*command];
        if line == "ok" || line.starts_with("error: ") {
            if line != reply.closer {
                return Err(format!(
                    "reply {reply_index} ({command:?}) closed with {line:?}, expected {:?}",
                    reply.closer
                ));
            }
            reply_index += 1;
            cursor = 0;
            continue;
        }
        match reply.data.iter().skip(cursor).position(|d| d == line) {
            Some(k) => cursor += k + 1,
            None => {
                return Err(format!(
                    "{line:?} is not a line of reply {reply_index} ({command:?}) at its place"
                ));
            }
        }
        audit.data_lines += 1;
    }
    if reply_index != sent.len() {
        return Err(format!(
            "{} lines typed, {reply_index} closing replies",
            sent.len()
        ));
    }
    if audit.data_lines + audit.dropped_lines_reported != audit.data_lines_expected {
        return Err(format!(
            "{} data lines received + {} reported dropped != {} expected",
            audit.data_lines, audit.dropped_lines_reported, audit.data_lines_expected
        ));
    }
    Ok(audit)
}
