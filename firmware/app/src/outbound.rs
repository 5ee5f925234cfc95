//! The one outbound path to the host: a bounded queue of whole text lines
//! (replies and notices) between the tasks that produce them and the
//! console's writer.
//!
//! Producers (the sequencer, the console's own line checks) push complete
//! lines with try semantics: a push never waits, so a host that stops
//! reading can never delay the sequencer, servo or galvo tasks. The
//! console's writer takes one line at a time and writes it whole to the
//! host, so a line is never cut: a line either reaches the host complete or
//! is dropped before its first byte is written.
//!
//! Room is shared by priority: data lines may use the queue up to
//! [`DATA_LIMIT`] bytes, notices up to [`NOTICE_LIMIT`], and the closing
//! `ok` / `error:` all of it. The console dispatches a command only while
//! [`CLOSER_ROOM`] bytes are free ([`Outbound::has_closer_room`]), and only
//! one command is in flight, so every closer fits: the protocol "zero or
//! more data lines, then exactly one `ok` or `error:` per input line, in
//! order" holds whatever the host does. Dropped data lines and notices are
//! counted; the writer reports them, where they were dropped, with a
//! bracketed notice once the host reads again.

use core::cell::RefCell;
use core::fmt;

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use heapless::Deque;

pub use self::dropped::Dropped;
use self::dropped::dropped_notice;
pub use self::line::{LineKind, OutLine};
use self::quiet::Quiet;
pub use self::quiet::QuietReply;
use crate::text::{REPLY_LINE_LEN, ReplyText, reply_text};

mod dropped;
mod line;
mod quiet;

/// Size of the outbound queue, bytes (lines are stored with a 2-byte
/// header). Holds the longest reply (`params`, about 5.5 KiB stored) with
/// room to spare, so a host that reads gets every line.
pub const OUTBOUND_BYTES: usize = 10 * 1024;

/// Stored size of the longest line (header + text), bytes.
const LINE_ENTRY_MAX: usize = HEADER + REPLY_LINE_LEN;
/// Header of a stored entry: kind, text length.
const HEADER: usize = 2;
/// Stored size of a drop marker (header + two u32 counters), bytes.
const MARKER_ENTRY: usize = HEADER + 8;

/// Bytes that only a closing `ok` / `error:` (with a drop marker before
/// it) may use.
pub const CLOSER_ROOM: usize = LINE_ENTRY_MAX + MARKER_ENTRY;
/// Notices may fill the queue up to this many bytes.
pub const NOTICE_LIMIT: usize = OUTBOUND_BYTES - CLOSER_ROOM;
/// Data lines may fill the queue up to this many bytes (the rest is kept
/// for four notices and the closer).
pub const DATA_LIMIT: usize = NOTICE_LIMIT - 4 * (LINE_ENTRY_MAX + MARKER_ENTRY);

/// Room a line's reply is given before the line is taken while the host
/// reads, bytes (grbl's longest, `$$`, stores about 700; the product's
/// long replies wait for the queue to drain instead).
pub const REPLY_ROOM: usize = 1024;

/// Bytes of the queue a `kind` line may fill.
fn limit(kind: LineKind) -> usize {
    match kind {
        LineKind::Data => DATA_LIMIT,
        LineKind::Notice => NOTICE_LIMIT,
        LineKind::Ok | LineKind::Error | LineKind::GrblError => OUTBOUND_BYTES,
    }
}

/// Entry code of a drop marker.
const MARKER_CODE: u8 = 0xff;

struct Queue {
    bytes: Deque<u8, OUTBOUND_BYTES>,
    /// Dropped since the last line that was queued (reported by a marker
    /// before the next queued line, or by the writer once the queue is
    /// empty).
    dropped: Dropped,
    /// A command was dispatched and has not been closed yet.
    awaiting_close: bool,
    /// The command in flight belongs to a host session that ended: its
    /// data lines and closer are discarded when they come.
    orphaned: bool,
    /// Lines taken by the writer (wrapping): the host reads while it grows.
    taken: u32,
    /// The quiet command in flight, if any, and the last one's reply
    /// (see [`Outbound::begin_quiet_command`]).
    quiet: Quiet,
}

impl Queue {
    const fn new() -> Self {
        Self {
            bytes: Deque::new(),
            dropped: Dropped {
                data_lines: 0,
                notices: 0,
            },
            awaiting_close: false,
            orphaned: false,
            taken: 0,
            quiet: Quiet::new(),
        }
    }

    fn push_bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            // Room was checked by the caller.
            let _ = self.bytes.push_back(b);
        }
    }

    /// Queues `text` as a `kind` line, after a drop marker if lines were
    /// dropped before it; counts it as dropped when its share is full.
    fn push(&mut self, kind: LineKind, text: &str) -> bool {
        if self.orphaned && kind != LineKind::Notice {
            // Nobody asked for it any more; not a drop to report.
            self.orphaned = !kind.is_closer();
            return true;
        }
        // At most REPLY_LINE_LEN bytes, cut on a character boundary.
        let mut end = text.len().min(REPLY_LINE_LEN);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let text = text.as_bytes().get(..end).unwrap_or(&[]);
        let marker = if self.dropped.is_empty() {
            0
        } else {
            MARKER_ENTRY
        };
        let needed = marker + HEADER + text.len();
        if self.bytes.len() + needed > limit(kind) {
            self.dropped.count(kind);
            return false;
        }
        if marker > 0 {
            let d = core::mem::take(&mut self.dropped);
            self.push_bytes(&[MARKER_CODE, 8]);
            self.push_bytes(&d.data_lines.to_le_bytes());
            self.push_bytes(&d.notices.to_le_bytes());
        }
        // `text` is at most REPLY_LINE_LEN (< 256) bytes.
        self.push_bytes(&[kind.code(), text.len() as u8]);
        self.push_bytes(text);
        true
    }

    fn pop_bytes<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        for b in out.iter_mut() {
            *b = self.bytes.pop_front().unwrap_or(0);
        }
        out
    }

    /// A new host session: drops every queued entry but notices (no
    /// command owns them), keeps the count of notices dropped, orphans the
    /// command in flight; returns whether there was one.
    fn new_session(&mut self) -> bool {
        let mut notices_dropped = self.dropped.notices;
        let mut left = self.bytes.len();
        while left >= HEADER {
            let [code, len] = self.pop_bytes::<2>();
            left = left.saturating_sub(HEADER + usize::from(len));
            let keep = code == LineKind::Notice.code();
            if code == MARKER_CODE {
                let _lines = self.pop_bytes::<4>();
                let notices = u32::from_le_bytes(self.pop_bytes::<4>());
                notices_dropped = notices_dropped.saturating_add(notices);
                continue;
            }
            if keep {
                self.push_bytes(&[code, len]);
            }
            for _ in 0..len {
                let byte = self.bytes.pop_front().unwrap_or(b'?');
                if keep {
                    // Room: the entry's bytes were just taken out.
                    let _ = self.bytes.push_back(byte);
                }
            }
        }
        self.dropped = Dropped {
            data_lines: 0,
            notices: notices_dropped,
        };
        self.orphaned = self.awaiting_close;
        self.awaiting_close
    }

    /// Takes the oldest entry: a line, or a drop marker turned into its
    /// notice. With an empty queue, reports drops not yet reported.
    fn pop(&mut self) -> Option<OutLine> {
        let line = self.pop_entry();
        if line.is_some() {
            self.taken = self.taken.wrapping_add(1);
        }
        line
    }

    fn pop_entry(&mut self) -> Option<OutLine> {
        let Some([code, len]) = (self.bytes.len() >= HEADER).then(|| self.pop_bytes::<2>()) else {
            if self.dropped.is_empty() {
                return None;
            }
            let d = core::mem::take(&mut self.dropped);
            return Some(dropped_notice(d));
        };
        if code == MARKER_CODE {
            let lines = u32::from_le_bytes(self.pop_bytes::<4>());
            let notices = u32::from_le_bytes(self.pop_bytes::<4>());
            return Some(dropped_notice(Dropped {
                data_lines: lines,
                notices,
            }));
        }
        let mut text = ReplyText::new();
        let mut utf8 = heapless::Vec::<u8, REPLY_LINE_LEN>::new();
        for _ in 0..len {
            let _ = utf8.push(self.bytes.pop_front().unwrap_or(b'?'));
        }
        // Lines were queued from `&str`s, whole: always valid UTF-8.
        let _ = text.push_str(core::str::from_utf8(&utf8).unwrap_or("?"));
        Some(OutLine {
            kind: LineKind::from_code(code).unwrap_or(LineKind::Data),
            text,
        })
    }
}

/// Who queues a line, which decides whether it belongs to the command in
/// flight.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// The reply of the command in flight (or a notice), from whichever
    /// task runs it: a closer ends the command, and the lines of a quiet
    /// command (the PELCO port's) are kept from the host.
    Command,
    /// Not the command in flight's, straight to the host: the console
    /// answering a line itself without dispatching it (a parse error, a
    /// refused line, `pelco status`), a realtime report (`?`, the lines
    /// of a soft reset). It never closes the command in flight nor counts
    /// as a quiet command's reply (a PELCO `get` in flight at boot once
    /// took the console's error for a bad line as its own, and the
    /// `get`'s reply went to the host instead).
    Direct,
}

/// The outbound line queue (usable in a `static`).
pub struct Outbound {
    queue: Mutex<CriticalSectionRawMutex, RefCell<Queue>>,
    /// A line was queued (wakes the writer).
    queued: Signal<CriticalSectionRawMutex, ()>,
    /// Room was freed or a reply closed (wakes the console's reader).
    freed: Signal<CriticalSectionRawMutex, ()>,
}

impl Outbound {
    /// An empty queue.
    pub const fn new() -> Self {
        Self {
            queue: Mutex::new(RefCell::new(Queue::new())),
            queued: Signal::new(),
            freed: Signal::new(),
        }
    }

    fn with<T>(&self, f: impl FnOnce(&mut Queue) -> T) -> T {
        self.queue.lock(|q| f(&mut q.borrow_mut()))
    }

    /// Queues one line of the command in flight's reply without waiting;
    /// `false` when it was dropped (and counted) because its share of the
    /// queue is full. A closer also ends the command in flight.
    pub fn push(&self, kind: LineKind, text: &str) -> bool {
        self.push_from(Origin::Command, kind, text)
    }

    /// Queues one line from `origin` without waiting (see [`Origin`]);
    /// `false` when it was dropped and counted.
    pub fn push_from(&self, origin: Origin, kind: LineKind, text: &str) -> bool {
        let mut quiet = false;
        let queued = self.with(|q| {
            if origin == Origin::Command {
                if kind.is_closer() {
                    q.awaiting_close = false;
                }
                quiet = q.quiet.keep(kind, text);
            }
            quiet || q.push(kind, text)
        });
        if quiet {
            if kind.is_closer() {
                self.freed.signal(());
            }
            return true;
        }
        if queued {
            self.queued.signal(());
        } else {
            crate::log::debug!("outbound: host not reading, {:?} line dropped", kind);
        }
        if kind.is_closer() {
            self.freed.signal(());
        }
        queued
    }

    /// Queues a line of the command in flight formatted from `args` (cut
    /// at [`REPLY_LINE_LEN`]).
    pub fn push_fmt(&self, kind: LineKind, args: fmt::Arguments<'_>) -> bool {
        self.push_fmt_from(Origin::Command, kind, args)
    }

    /// Queues a line from `origin` formatted from `args` (cut at
    /// [`REPLY_LINE_LEN`]).
    pub fn push_fmt_from(&self, origin: Origin, kind: LineKind, args: fmt::Arguments<'_>) -> bool {
        self.push_from(origin, kind, &reply_text(args))
    }

    /// Takes the next line to write (drop reports included), if any.
    pub fn take(&self) -> Option<OutLine> {
        let line = self.with(Queue::pop);
        if line.is_some() {
            self.freed.signal(());
        }
        line
    }

    /// Waits until a line (or a drop report) can be taken.
    pub async fn next_line(&self) -> OutLine {
        loop {
            if let Some(line) = self.take() {
                return line;
            }
            self.queued.wait().await;
        }
    }

    /// Bytes queued and not yet taken by the writer.
    pub fn queued_bytes(&self) -> usize {
        self.with(|q| q.bytes.len())
    }

    /// Whether a closer (and a drop marker before it) still fits beyond
    /// what notices may fill: the console dispatches a line only then.
    pub fn has_closer_room(&self) -> bool {
        self.queued_bytes() <= OUTBOUND_BYTES - CLOSER_ROOM
    }

    /// Whether the reply of a line (up to [`REPLY_ROOM`] bytes of data
    /// lines and its closer) fits: the console waits for it while the host
    /// reads before it takes the next line.
    pub fn has_reply_room(&self) -> bool {
        self.queued_bytes() + REPLY_ROOM <= DATA_LIMIT
    }

    /// Lines dropped and not yet reported.
    pub fn unreported_drops(&self) -> Dropped {
        self.with(|q| q.dropped)
    }

    /// Lines the writer has taken so far (wrapping): while it does not
    /// change the host reads nothing.
    pub fn lines_taken(&self) -> u32 {
        self.with(|q| q.taken)
    }

    /// Starts a new host session (a host connected): the replies still
    /// queued for the last one are discarded (notices are kept: faults
    /// belong to no session), and a command still in flight answers no
    /// one: its data lines and closer are discarded when they come.
    /// Returns whether a command was in flight (the console stops it).
    pub fn new_session(&self) -> bool {
        let in_flight = self.with(Queue::new_session);
        self.freed.signal(());
        in_flight
    }

    /// Marks a command as dispatched: its closer is awaited.
    pub fn begin_command(&self) {
        self.with(|q| q.awaiting_close = true);
    }

    /// Whether a dispatched command has not been closed yet.
    pub fn awaiting_close(&self) -> bool {
        self.with(|q| q.awaiting_close)
    }

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
            q.quiet.begin();
            true
        })
    }

    /// The reply of the last quiet command once it is closed (taken once).
    pub fn take_quiet_reply(&self) -> Option<QuietReply> {
        self.with(|q| q.quiet.take_reply())
    }

    /// Waits until `ready` holds, re-checking whenever room is freed or a
    /// reply closes.
    pub async fn wait_until(&self, mut ready: impl FnMut(&Self) -> bool) {
        while !ready(self) {
            self.freed.wait().await;
        }
    }
}

impl Default for Outbound {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests;
