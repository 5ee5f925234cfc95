//! The command channel: the one path from the command line to the rest of
//! the firmware, and the reply path back.
//!
//! The console task parses a line into a [`Command`], sends it on
//! [`CommandLink::commands`] and then forwards [`Reply`] items from
//! [`CommandLink::replies`] until the closing `ok` / `error:`; the sequencer
//! task receives commands (also while a pattern runs, so a new command
//! preempts it) and answers each with exactly one closing reply.

use core::fmt::{self, Write as _};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;

/// Longest reply line, bytes (longer lines are cut).
pub const REPLY_LINE_LEN: usize = 120;

/// Text of one reply line.
pub type ReplyText = heapless::String<REPLY_LINE_LEN>;

/// A parsed, validated command for the sequencer.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Command {
    /// List the commands.
    Help,
    /// Firmware version and build.
    Version,
    /// Uptime, build and current state.
    Status,
}

/// One item of a reply. Every command gets zero or more `Data` lines and
/// then exactly one `Ok` or `Error`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Reply {
    /// An informational line (printed as is).
    Data(ReplyText),
    /// The command succeeded (printed as `ok`).
    Ok,
    /// The command failed (printed as `error: <reason>`).
    Error(ReplyText),
}

impl Reply {
    /// Whether this item closes the reply.
    pub fn is_final(&self) -> bool {
        !matches!(self, Reply::Data(_))
    }
}

/// Formats into a reply line, cutting it at [`REPLY_LINE_LEN`] bytes.
pub fn reply_text(args: fmt::Arguments<'_>) -> ReplyText {
    let mut out = Truncating(ReplyText::new());
    let _ = out.write_fmt(args);
    out.0
}

struct Truncating(ReplyText);

impl fmt::Write for Truncating {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for c in s.chars() {
            if self.0.push(c).is_err() {
                break;
            }
        }
        Ok(())
    }
}

/// Depth of the command queue. One command is in flight at a time (the
/// console waits for its reply), so a small queue suffices.
pub const COMMAND_QUEUE_DEPTH: usize = 2;
/// Depth of the reply queue.
pub const REPLY_QUEUE_DEPTH: usize = 4;

/// Channels between the console task and the sequencer task.
pub struct CommandLink {
    /// Console → sequencer.
    pub commands: Channel<CriticalSectionRawMutex, Command, COMMAND_QUEUE_DEPTH>,
    /// Sequencer → console.
    pub replies: Channel<CriticalSectionRawMutex, Reply, REPLY_QUEUE_DEPTH>,
}

impl CommandLink {
    /// Empty channels (usable in a `static`).
    pub const fn new() -> Self {
        Self {
            commands: Channel::new(),
            replies: Channel::new(),
        }
    }

    /// Sends one data line of the current reply.
    pub async fn data(&self, args: fmt::Arguments<'_>) {
        self.replies.send(Reply::Data(reply_text(args))).await;
    }

    /// Closes the current reply with `ok`.
    pub async fn ok(&self) {
        self.replies.send(Reply::Ok).await;
    }

    /// Closes the current reply with `error: <reason>`.
    pub async fn error(&self, reason: impl fmt::Display) {
        self.replies
            .send(Reply::Error(reply_text(format_args!("{reason}"))))
            .await;
    }
}

impl Default for CommandLink {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reply_text_is_cut_at_the_limit() {
        let long = [b'x'; 300];
        let text = core::str::from_utf8(&long).unwrap_or("");
        let line = reply_text(format_args!("{text}"));
        assert_eq!(line.len(), REPLY_LINE_LEN);
        assert_eq!(
            reply_text(format_args!("a={} b={}", 1, 2.5)).as_str(),
            "a=1 b=2.5"
        );
    }

    #[test]
    fn only_ok_and_error_close_a_reply() {
        assert!(Reply::Ok.is_final());
        assert!(Reply::Error(ReplyText::new()).is_final());
        assert!(!Reply::Data(ReplyText::new()).is_final());
    }
}
