//! Quiet commands: commands another task than the console (the PELCO
//! port) sends through the command channel, their replies kept from the
//! host and handed to the sender.

use super::line::LineKind;
use crate::text::{REPLY_LINE_LEN, ReplyText};

/// The reply of a quiet command (sent by another task than the console):
/// its first data line and how it closed.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct QuietReply {
    /// First data line (empty when there was none).
    pub data: ReplyText,
    /// `Some(true)` once closed with `ok`, `Some(false)` with an error.
    pub closed: Option<bool>,
}

/// The queue's quiet-command state.
pub(super) struct Quiet {
    /// The command in flight is quiet.
    active: bool,
    /// The reply of the last quiet command, kept from the host.
    reply: QuietReply,
}

impl Quiet {
    /// No quiet command yet.
    pub(super) const fn new() -> Self {
        Self {
            active: false,
            reply: QuietReply {
                data: ReplyText::new(),
                closed: None,
            },
        }
    }

    /// A quiet command was dispatched: its reply starts empty.
    pub(super) fn begin(&mut self) {
        self.active = true;
        self.reply = QuietReply::default();
    }

    /// Keeps a line of the quiet command in flight from the host; `false`
    /// when the line is not part of one (notices never are).
    pub(super) fn keep(&mut self, kind: LineKind, text: &str) -> bool {
        if !self.active || kind == LineKind::Notice {
            return false;
        }
        if kind.is_closer() {
            self.active = false;
            self.reply.closed = Some(kind == LineKind::Ok);
        } else if self.reply.data.is_empty() {
            let _ = self
                .reply
                .data
                .push_str(text.get(..REPLY_LINE_LEN).unwrap_or(text));
        }
        true
    }

    /// The last quiet command's reply once it is closed (taken once).
    pub(super) fn take_reply(&mut self) -> Option<QuietReply> {
        self.reply.closed?;
        Some(core::mem::take(&mut self.reply))
    }
}
