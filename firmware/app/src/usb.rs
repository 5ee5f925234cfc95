//! The USB CDC-ACM command-line task body: bytes from the host → lines →
//! [`Command`](crate::command::Command)s on the command channel; replies and
//! notices from the [outbound queue](crate::outbound) back to the host.
//!
//! Generic over `embedded_io_async` so the same code runs on the USB CDC-ACM
//! class on the target and on the simulated host's pipes.
//!
//! Protocol: every line gets zero or more data lines and then exactly one
//! `ok` or `error: <reason>`, in order. Unsolicited notices (servo faults
//! and recoveries, lines dropped while the host was not reading) are
//! printed in brackets: `[error: …]`, `[info: …]`.
//!
//! Reading and writing run side by side: the writer takes one whole line
//! at a time from the outbound queue and writes it completely (a line is
//! never cut, however long the host stops reading); the reader keeps
//! taking lines and running commands meanwhile. Nothing here can make the
//! sequencer wait: it queues its lines without waiting (see
//! [`crate::outbound`]). When the host stops reading, data lines that no
//! longer fit are dropped, counted and reported where they were dropped;
//! closers are never dropped, because the reader takes the next line only
//! when its closer has room (so the host's input waits instead).

use embassy_futures::select::{Either, select};
use embassy_time::{Duration, with_timeout};
use embedded_io_async::{Read, Write};

use crate::cli::line::LineAssembler;
use crate::cli::parse::parse_line;
use crate::command::{CommandLink, REPLY_LINE_LEN};
use crate::log;
use crate::outbound::{LineKind, OutLine, Outbound};

/// Before a command whose reply has data lines, the console waits this long
/// at most for earlier output to reach the host, so a host that reads
/// (even slowly) gets every line; after it the host counts as not reading
/// and the command runs anyway (lines that do not fit are dropped and
/// counted). Commands without data lines (`stop`, `goto`, …) never wait.
pub const HOST_STALL: Duration = Duration::from_millis(250);

/// Longest line on the wire without its line end: `error: ` + text, bytes.
const WIRE_LINE_MAX: usize = 7 + REPLY_LINE_LEN;

/// Why the console stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConsoleEnd {
    /// The input reached end of file (host simulator: end of script/stdin).
    EndOfInput,
    /// Reading failed (USB: host disconnected).
    ReadFailed,
    /// Writing failed (USB: host disconnected).
    WriteFailed,
}

/// Serves the command line until the input ends or reading or writing
/// fails. Each complete line gets exactly one closing reply (`ok` or
/// `error: …`), possibly preceded by data lines. Lines still queued when it
/// ends are written by the next call (after a USB reconnect).
pub async fn run_console<R: Read, W: Write>(
    rx: &mut R,
    tx: &mut W,
    link: &CommandLink,
) -> ConsoleEnd {
    match select(read_lines(rx, link), write_lines(tx, &link.outbound)).await {
        Either::First(end) | Either::Second(end) => end,
    }
}

/// Reads lines and dispatches them, one command in flight at a time.
async fn read_lines<R: Read>(rx: &mut R, link: &CommandLink) -> ConsoleEnd {
    let out = &link.outbound;
    // A command sent before a reconnect is answered first.
    out.wait_until(|o| !o.awaiting_close()).await;
    let mut assembler = LineAssembler::new();
    let mut chunk = [0u8; 64];
    loop {
        let n = match rx.read(&mut chunk).await {
            Ok(0) => return ConsoleEnd::EndOfInput,
            Ok(n) => n,
            Err(_) => return ConsoleEnd::ReadFailed,
        };
        for &byte in chunk.iter().take(n) {
            let Some(line) = assembler.push(byte) else {
                continue;
            };
            // The closer of this line must fit: until it does, the host's
            // input waits (it is not reading its replies either).
            out.wait_until(Outbound::has_closer_room).await;
            match line {
                Err(e) => link.error(e),
                Ok(line) => dispatch(line.as_str(), link).await,
            }
        }
    }
}

/// Parses one line and runs it; returns once its reply is closed (queued,
/// not necessarily written).
async fn dispatch(line: &str, link: &CommandLink) {
    let out = &link.outbound;
    let command = match parse_line(line) {
        Ok(Some(command)) => command,
        Ok(None) => return link.ok(),
        Err(e) => {
            log::debug!("refused line: {}", e);
            return link.error(e);
        }
    };
    if command.replies_with_data() && out.queued_bytes() > 0 {
        let drained = with_timeout(HOST_STALL, out.wait_until(|o| o.queued_bytes() == 0)).await;
        if drained.is_err() {
            log::warning!("usb: host is not reading; replies may be dropped");
        }
    }
    // No await between marking and sending: a console cancelled by a
    // disconnect cannot leave a command marked but unsent.
    out.begin_command();
    if link.commands.try_send(command).is_err() {
        // Cannot happen with one command in flight; answered all the same.
        link.error("busy: the command queue is full");
        return;
    }
    out.wait_until(|o| !o.awaiting_close()).await;
}

/// Writes queued lines, each whole, until writing fails.
async fn write_lines<W: Write>(tx: &mut W, out: &Outbound) -> ConsoleEnd {
    loop {
        let line = out.next_line().await;
        if write_line(tx, &line).await.is_err() {
            return ConsoleEnd::WriteFailed;
        }
    }
}

/// Writes one line with its decoration (`error: `, `[…]`), then CR LF,
/// then flushes; never abandoned part way (only a failed write ends it).
/// The line end goes in a write of its own so the line always ends in a
/// short USB packet, which makes the host deliver it at once (a line
/// ending exactly on a full packet would wait for the next one: the
/// CDC-ACM class sends no zero-length packet).
async fn write_line<W: Write>(tx: &mut W, line: &OutLine) -> Result<(), W::Error> {
    let (prefix, suffix): (&[u8], &[u8]) = match line.kind {
        LineKind::Data => (b"", b""),
        LineKind::Ok => (b"ok", b""),
        LineKind::Error => (b"error: ", b""),
        LineKind::Notice => (b"[", b"]"),
    };
    let text: &[u8] = match line.kind {
        LineKind::Ok => b"",
        _ => line.text.as_bytes(),
    };
    let mut wire = heapless::Vec::<u8, WIRE_LINE_MAX>::new();
    for part in [prefix, text, suffix] {
        // Fits: the text is at most REPLY_LINE_LEN bytes.
        let _ = wire.extend_from_slice(part);
    }
    tx.write_all(&wire).await?;
    tx.write_all(b"\r\n").await?;
    tx.flush().await
}
