//! (c) One reply per line.

use std::collections::VecDeque;

use super::violation::{Violation, ViolationKind};
use crate::usb_host::Transcript;
/// (c) Exactly one closing reply per line, in order; notices are whole
/// `[…]` lines. grbl's realtime bytes (`>> 0xNN`, typed by `@realtime`)
/// owe no reply, and what they answer (status reports `<…>`, `ALARM:N`,
/// the `Grbl …` banner of a soft reset) may come between lines.
pub(super) fn one_reply_per_line(transcript: &Transcript) -> Vec<Violation> {
    let mut found = Vec::new();
    let mut add = |t_us: u64, detail: String| {
        found.push(Violation {
            kind: ViolationKind::Replies,
            t_us,
            detail,
        })
    };
    // Lines awaiting their closing reply, oldest first (a host may type
    // ahead), and the line closed last.
    let mut pending: VecDeque<(u64, &str)> = VecDeque::new();
    let mut last_closed: Option<&str> = None;
    for (t, line) in &transcript.lines {
        let t = *t;
        if let Some(sent) = line.strip_prefix("> ") {
            pending.push_back((t, sent));
            continue;
        }
        if line.starts_with('[') {
            if !line.ends_with(']') {
                add(t, format!("notice cut or glued to a reply: {line:?}"));
            }
            continue;
        }
        let unsolicited =
            line.starts_with('<') || line.starts_with("ALARM:") || line.starts_with("Grbl ");
        if line.starts_with(">> ") || (unsolicited && pending.is_empty()) {
            continue;
        }
        let closing = line == "ok" || line.starts_with("error:");
        if closing && let Some((_, sent)) = pending.pop_front() {
            last_closed = Some(sent);
            continue;
        }
        if !pending.is_empty() {
            // A data line of the oldest line awaiting its reply.
            continue;
        }
        let detail = match (closing, last_closed) {
            (true, Some(sent)) => format!("{sent:?} got a second closing reply {line:?}"),
            (false, Some(sent)) => format!("line {line:?} after the closing reply of {sent:?}"),
            (_, None) => format!("{line:?} before any command line"),
        };
        add(t, detail);
    }
    for (t, sent) in pending {
        add(t, format!("{sent:?} got no closing reply"));
    }
    found
}
