//! The USB CDC-ACM command-line task body: bytes from the host → lines →
//! [`Command`]s on the command channel; replies and
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
use embassy_time::{Duration, Instant, Timer, with_timeout};
use embedded_io_async::{Read, Write};

use heapless::Deque;

use crate::cli::line::{LineAssembler, LineError};
use crate::cli::parse::parse_line;
use crate::command::{Command, CommandLink, GrblLine, RealtimeRequest};
use crate::grbl::classify::{LineKind, classify};
use crate::grbl::realtime::{self, Filtered, Realtime};
use crate::grbl::report::BANNER;
use crate::grbl::{GrblError, RX_BUFFER_BYTES};
use crate::log;
use crate::outbound::{LineKind as OutKind, OutLine, Outbound};
use crate::text::REPLY_LINE_LEN;

mod flow;
use flow::{HostReading, OwedClosers};

/// A host that reads nothing for this long counts as not reading (until it
/// reads a line again). Before a command whose reply has data lines, the
/// console waits this long at most for earlier output to reach the host,
/// so a host that reads (even slowly) gets every line; and a line that
/// finds no room for its closer waits for room (its host's input waits:
/// back-pressure) as long as the host reads a line within this time.
/// Once the host counts as not reading, data commands run at once (lines
/// that do not fit are dropped and counted) and lines without room for a
/// closer are refused: the wait is paid once per stall, so lines typed
/// behind many commands (a `stop`) are not held back by each.
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

/// Serves the command line to one host session until the input ends or
/// reading or writing fails. Each complete line gets exactly one closing
/// reply (`ok` or `error: …`), possibly preceded by data lines. A session
/// starts afresh: replies still queued for an earlier one are dropped
/// (notices kept), and a command of an earlier one still running is
/// stopped (as `stop` does) and its reply dropped, so a host that opens
/// the port again is answered at once whatever the last one left.
pub async fn run_console<R: Read, W: Write>(
    rx: &mut R,
    tx: &mut W,
    link: &CommandLink,
) -> ConsoleEnd {
    if link.outbound.new_session() {
        log::warning!("usb: the last session's command still runs: stopped");
        link.stop_request.signal(());
    }
    match select(read_lines(rx, link), write_lines(tx, &link.outbound)).await {
        Either::First(end) | Either::Second(end) => end,
    }
}

/// Reads lines and dispatches them, one command in flight at a time.
async fn read_lines<R: Read>(rx: &mut R, link: &CommandLink) -> ConsoleEnd {
    let out = &link.outbound;
    // The last session's command (stopped) is closed first.
    out.wait_until(|o| !o.awaiting_close()).await;
    let mut assembler = LineAssembler::new();
    let mut input = RxBuffer::new();
    let mut reading = HostReading::default();
    let mut owed = OwedClosers::default();
    loop {
        let Some(byte) = input.bytes.pop_front() else {
            let read = async {
                if owed.is_empty() {
                    Either::First(input.fill(rx, link).await)
                } else {
                    // Pay the owed closers as soon as the host reads again,
                    // even if it types nothing more.
                    select(
                        input.fill(rx, link),
                        out.wait_until(Outbound::has_closer_room),
                    )
                    .await
                }
            };
            match read.await {
                Either::First(Ok(Filled::Bytes)) => {}
                Either::First(Ok(Filled::SoftReset)) => assembler = LineAssembler::new(),
                Either::First(Err(end)) => return end,
                Either::Second(()) => owed.pay(link),
            }
            continue;
        };
        let Some(line) = assembler.push(byte) else {
            continue;
        };
        owed.pay(link);
        if owed.is_empty() && !out.has_reply_room() && !reading.not_reading(out) {
            // A host that reads gets room soon: wait for it.
            match wait_for_reply_room(rx, &mut input, link).await {
                Ok(Room::Free) => {}
                Ok(Room::Stalled) => {
                    log::warning!("usb: host is not reading; lines are refused");
                    reading.stalled(out);
                }
                Ok(Room::AfterReset) => {
                    // The line was typed before the soft reset: flushed,
                    // as grbl flushes its buffer.
                    assembler = LineAssembler::new();
                    continue;
                }
                Err(end) => return end,
            }
        }
        if !owed.is_empty() || !out.has_closer_room() {
            // The host types ahead but reads nothing, and its replies
            // fill the queue: this line cannot be answered in order
            // now. A `stop` still stops at once (as the button does);
            // every line is owed its closer, paid in order once the
            // host reads.
            let is_stop = matches!(
                line.as_ref().map(|l| parse_line(l.as_str())),
                Ok(Ok(Some(crate::command::Command::Stop)))
            );
            if is_stop {
                log::warning!("usb: stop typed while the host is not reading: stopping now");
                link.stop_request.signal(());
            }
            if owed.owe(is_stop) {
                continue;
            }
            // More alternations than it remembers: the host's input
            // waits until its replies fit.
            while !owed.is_empty() || !out.has_closer_room() {
                out.wait_until(Outbound::has_closer_room).await;
                owed.pay(link);
            }
        }
        match line {
            Err(LineError::TooLong)
                if classify(assembler.long_line_head()) != LineKind::Product =>
            {
                input.greet(link);
                link.direct_reply().grbl_error(GrblError::LineOverflow);
            }
            Err(e) => link.direct_reply().error(e),
            Ok(line) if classify(line.as_str()) == LineKind::Product => {
                dispatch(line.as_str(), link, &mut reading).await;
            }
            Ok(line) => match dispatch_grbl(line.as_str(), rx, &mut input, link).await {
                Ok(Filled::Bytes) => {}
                Ok(Filled::SoftReset) => assembler = LineAssembler::new(),
                Err(end) => return end,
            },
        }
    }
}

/// What [`RxBuffer::fill`] read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Filled {
    /// Bytes (possibly only realtime commands).
    Bytes,
    /// A soft reset (0x18): the bytes before it were dropped, as grbl
    /// flushes its buffer; the line being assembled must be too.
    SoftReset,
}

/// The console's input between the host and the line assembler (grbl's
/// RX buffer, [`RX_BUFFER_BYTES`]), with grbl's realtime bytes taken out as
/// they arrive. A host sending more than fits just waits (USB or PTY
/// back-pressure: nothing is lost).
struct RxBuffer {
    bytes: Deque<u8, RX_BUFFER_BYTES>,
    /// grbl's banner was sent on this connection (before the first grbl
    /// line or realtime byte; the product's own console prints none, so a
    /// session of product commands reads as it always did).
    greeted: bool,
}

impl RxBuffer {
    fn new() -> Self {
        Self {
            bytes: Deque::new(),
            greeted: false,
        }
    }

    /// Sends grbl's banner once per connection.
    fn greet(&mut self, link: &CommandLink) {
        if !core::mem::replace(&mut self.greeted, true) {
            link.direct_reply().data(format_args!("{BANNER}"));
        }
    }

    /// Reads what fits (waits while the buffer is full: back-pressure);
    /// realtime commands go to the sequencer at once.
    async fn fill<R: Read>(
        &mut self,
        rx: &mut R,
        link: &CommandLink,
    ) -> Result<Filled, ConsoleEnd> {
        let room = RX_BUFFER_BYTES - self.bytes.len();
        if room == 0 {
            return core::future::pending().await;
        }
        let mut chunk = [0u8; 64];
        let n = match rx.read(&mut chunk[..room.min(64)]).await {
            Ok(0) => return Err(ConsoleEnd::EndOfInput),
            Ok(n) => n,
            Err(_) => return Err(ConsoleEnd::ReadFailed),
        };
        let mut filled = Filled::Bytes;
        for item in realtime::split(chunk.get(..n).unwrap_or(&[])) {
            match item {
                Filtered::Line(byte) => {
                    // Room was checked before the read.
                    let _ = self.bytes.push_back(byte);
                }
                Filtered::Realtime(command) => {
                    if command == Realtime::SoftReset {
                        // The sequencer sends the banner after a reset.
                        self.greeted = true;
                        self.bytes.clear();
                        filled = Filled::SoftReset;
                    } else {
                        self.greet(link);
                    }
                    let rx_free_bytes = (RX_BUFFER_BYTES - self.bytes.len()) as u16;
                    let request = RealtimeRequest {
                        command,
                        rx_free_bytes,
                    };
                    if link.realtime.try_send(request).is_err() {
                        log::warning!("usb: realtime queue full, {:?} dropped", command);
                    }
                }
            }
        }
        Ok(filled)
    }
}

/// Sends a G-code or `$` line to the sequencer and waits for its closer
/// (`ok` once its motion is queued: with a full queue that is when room
/// frees), reading on meanwhile so realtime commands (`!`, `~`, `?`,
/// 0x18) act at once.
async fn dispatch_grbl<R: Read>(
    line: &str,
    rx: &mut R,
    input: &mut RxBuffer,
    link: &CommandLink,
) -> Result<Filled, ConsoleEnd> {
    let out = &link.outbound;
    input.greet(link);
    let Some(line) = GrblLine::new(line) else {
        link.direct_reply().grbl_error(GrblError::LineOverflow);
        return Ok(Filled::Bytes);
    };
    // A quiet command (the PELCO port's) may be in flight.
    out.wait_until(|o| !o.awaiting_close()).await;
    out.begin_command();
    if link.commands.try_send(Command::Grbl(line)).is_err() {
        link.error("busy: the command queue is full");
        return Ok(Filled::Bytes);
    }
    let mut filled = Filled::Bytes;
    loop {
        let closed = out.wait_until(|o| !o.awaiting_close());
        match select(closed, input.fill(rx, link)).await {
            Either::First(()) => return Ok(filled),
            Either::Second(Ok(Filled::Bytes)) => {}
            Either::Second(Ok(Filled::SoftReset)) => filled = Filled::SoftReset,
            Either::Second(Err(end)) => {
                out.wait_until(|o| !o.awaiting_close()).await;
                return Err(end);
            }
        }
    }
}

/// What [`wait_for_reply_room`] saw.
enum Room {
    /// A reply fits.
    Free,
    /// The host read nothing for [`HOST_STALL`].
    Stalled,
    /// A soft reset came (a reply fits).
    AfterReset,
}

/// Waits until a reply fits in the outbound queue while the host reads
/// (a line taken within each [`HOST_STALL`]), reading on meanwhile:
/// realtime bytes act at once, line bytes wait in the RX buffer and,
/// once it is full, in the host (back-pressure).
async fn wait_for_reply_room<R: Read>(
    rx: &mut R,
    input: &mut RxBuffer,
    link: &CommandLink,
) -> Result<Room, ConsoleEnd> {
    let out = &link.outbound;
    let mut reset = false;
    let mut taken = out.lines_taken();
    let mut deadline = Instant::now() + HOST_STALL;
    loop {
        if out.has_reply_room() {
            return Ok(if reset { Room::AfterReset } else { Room::Free });
        }
        if out.lines_taken() != taken {
            taken = out.lines_taken();
            deadline = Instant::now() + HOST_STALL;
        }
        let progress = out.wait_until(|o| o.has_reply_room() || o.lines_taken() != taken);
        let waited = select(select(progress, Timer::at(deadline)), input.fill(rx, link));
        match waited.await {
            Either::First(Either::First(())) | Either::Second(Ok(Filled::Bytes)) => {}
            Either::First(Either::Second(())) => return Ok(Room::Stalled),
            Either::Second(Ok(Filled::SoftReset)) => reset = true,
            Either::Second(Err(end)) => return Err(end),
        }
    }
}

/// Parses one line and runs it; returns once its reply is closed (queued,
/// not necessarily written). `reading`: see [`HOST_STALL`].
async fn dispatch(line: &str, link: &CommandLink, reading: &mut HostReading) {
    let out = &link.outbound;
    if line.split_whitespace().eq(["pelco", "status"]) {
        // Answered here: the port's counters are the console's to read.
        let reply = link.direct_reply();
        link.pelco.report(|args| reply.data(args));
        return reply.ok();
    }
    let command = match parse_line(line) {
        Ok(Some(command)) => command,
        Ok(None) => return link.direct_reply().ok(),
        Err(e) => {
            log::debug!("refused line: {}", e);
            return link.direct_reply().error(e);
        }
    };
    if command.replies_with_data() && out.queued_bytes() > 0 && !reading.not_reading(out) {
        let drained = with_timeout(HOST_STALL, out.wait_until(|o| o.queued_bytes() == 0)).await;
        if drained.is_err() {
            log::warning!("usb: host is not reading; replies may be dropped");
            reading.stalled(out);
        }
    }
    // A quiet command (the PELCO port's) may be in flight.
    out.wait_until(|o| !o.awaiting_close()).await;
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
        OutKind::Data => (b"", b""),
        OutKind::Ok => (b"ok", b""),
        OutKind::Error => (b"error: ", b""),
        OutKind::GrblError => (b"error:", b""),
        OutKind::Notice => (b"[", b"]"),
    };
    let text: &[u8] = match line.kind {
        OutKind::Ok => b"",
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
