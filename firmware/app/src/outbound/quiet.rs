//! Quiet commands: commands another task than the console (the PELCO
//! port) sends through the command channel, their replies kept from the
//! host and handed to the sender.

use super::{LineKind, Outbound, Queue};
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

impl Queue {
    /// Keeps a line of the quiet command in flight from the host; `false`
    /// when the line is not part of one (notices never are).
    pub(super) fn keep_quiet(&mut self, kind: LineKind, text: &str) -> bool {
        if !self.quiet || kind == LineKind::Notice {
            return false;
        }
        if kind.is_closer() {
            self.quiet = false;
            self.quiet_reply.closed = Some(kind == LineKind::Ok);
        } else if self.quiet_reply.data.is_empty() {
            let _ = self
                .quiet_reply
                .data
                .push_str(text.get(..REPLY_LINE_LEN).unwrap_or(text));
        }
        true
    }
}

impl Outbound {
    /// Marks a command from another task than the console (the PELCO
    /// port) as dispatched, when no command is in flight: its data lines
    /// and closer are kept from the host ([`Outbound::take_quiet_reply`]),
    /// and the console waits for its closer like for one of its own.
    /// `false` (nothing marked) while another command is in flight.
    pub fn begin_quiet_command(&self) -> bool {
        self.with(|q| {
            if q.awaiting_close {
                return false;
            }
            q.awaiting_close = true;
            q.quiet = true;
            q.quiet_reply = QuietReply::default();
            true
        })
    }

    /// The reply of the last quiet command once it is closed (taken once).
    pub fn take_quiet_reply(&self) -> Option<QuietReply> {
        self.with(|q| {
            q.quiet_reply.closed?;
            Some(core::mem::take(&mut q.quiet_reply))
        })
    }
}
