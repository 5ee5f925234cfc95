//! An answerer's lines into the outbound queue: the reply of the command
//! in flight, or a line that goes straight to the host (see [`Origin`]).

use core::fmt;

use crate::outbound::{LineKind, Origin, Outbound};
use crate::text::ReplyText;

/// One answerer's lines into the outbound queue (see [`Origin`]).
#[derive(Clone, Copy)]
pub struct Reply<'a> {
    outbound: &'a Outbound,
    origin: Origin,
}

impl<'a> Reply<'a> {
    /// `origin`'s lines into `outbound`.
    pub const fn new(outbound: &'a Outbound, origin: Origin) -> Self {
        Self { outbound, origin }
    }
}

impl Reply<'_> {
    /// Queues one data line (never waits; dropped and counted when the
    /// host is not reading and the queue is full).
    pub fn data(self, args: fmt::Arguments<'_>) {
        self.outbound
            .push_fmt_from(self.origin, LineKind::Data, args);
    }

    /// Queues one data line already formatted (never waits, like
    /// [`Reply::data`]).
    pub fn data_line(self, line: ReplyText) {
        self.outbound.push_from(self.origin, LineKind::Data, &line);
    }

    /// Closes the reply with `ok` (never waits; a closer always has room).
    pub fn ok(self) {
        self.outbound.push_from(self.origin, LineKind::Ok, "");
    }

    /// Closes the reply with grbl's `error:N` (never waits; a closer
    /// always has room).
    pub fn grbl_error(self, error: crate::grbl::GrblError) {
        self.outbound.push_fmt_from(
            self.origin,
            LineKind::GrblError,
            format_args!("{}", u32::from(error.code())),
        );
    }

    /// Closes the reply with `error: <reason>` (never waits; a closer
    /// always has room).
    pub fn error(self, reason: impl fmt::Display) {
        self.outbound
            .push_fmt_from(self.origin, LineKind::Error, format_args!("{reason}"));
    }
}
