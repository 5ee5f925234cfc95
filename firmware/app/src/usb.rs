//! The USB CDC-ACM command-line task body: bytes from the host → lines →
//! [`Command`](crate::command::Command)s on the command channel; replies back
//! to the host.
//!
//! Generic over `embedded_io_async` so the same code runs on the USB CDC-ACM
//! class on the target and on the simulated host's pipes.
//!
//! Protocol: every line gets zero or more data lines and then exactly one
//! `ok` or `error: <reason>`. Unsolicited notices (servo faults and
//! recoveries) are printed between replies in brackets: `[error: …]`,
//! `[info: …]`.

use embassy_futures::select::{Either, select};
use embassy_time::{Duration, with_timeout};
use embedded_io_async::{Read, Write};

use crate::cli::line::LineAssembler;
use crate::cli::parse::parse_line;
use crate::command::{CommandLink, Reply, ReplyText};
use crate::log;

/// A reply write that takes longer than this (host not reading) is dropped,
/// so a stalled terminal can never stall the sequencer.
pub const WRITE_TIMEOUT: Duration = Duration::from_millis(500);

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

/// Serves the command line until the input ends or fails. Each complete
/// line gets exactly one closing reply (`ok` or `error: …`), possibly
/// preceded by data lines.
pub async fn run_console<R: Read, W: Write>(
    rx: &mut R,
    tx: &mut W,
    link: &CommandLink,
) -> ConsoleEnd {
    let mut assembler = LineAssembler::new();
    let mut chunk = [0u8; 64];
    loop {
        let n = match select(rx.read(&mut chunk), link.events.receive()).await {
            Either::First(Ok(0)) => return ConsoleEnd::EndOfInput,
            Either::First(Ok(n)) => n,
            Either::First(Err(_)) => return ConsoleEnd::ReadFailed,
            Either::Second(notice) => {
                if write_notice(tx, &notice).await.is_err() {
                    return ConsoleEnd::WriteFailed;
                }
                continue;
            }
        };
        for &byte in chunk.iter().take(n) {
            let Some(line) = assembler.push(byte) else {
                continue;
            };
            let outcome = match line {
                Err(e) => {
                    write_reply(
                        tx,
                        &Reply::Error(crate::command::reply_text(format_args!("{e}"))),
                    )
                    .await
                }
                Ok(line) => handle_line(line.as_str(), tx, link).await,
            };
            if outcome.is_err() {
                return ConsoleEnd::WriteFailed;
            }
        }
    }
}

/// Parses and dispatches one line, then forwards its reply.
async fn handle_line<W: Write>(line: &str, tx: &mut W, link: &CommandLink) -> Result<(), W::Error> {
    let command = match parse_line(line) {
        Ok(Some(command)) => command,
        Ok(None) => return write_reply(tx, &Reply::Ok).await,
        Err(e) => {
            log::debug!("refused line: {}", e);
            return write_reply(
                tx,
                &Reply::Error(crate::command::reply_text(format_args!("{e}"))),
            )
            .await;
        }
    };
    link.commands.send(command).await;
    let mut writable = true;
    loop {
        let reply = link.replies.receive().await;
        if writable {
            match with_timeout(WRITE_TIMEOUT, write_reply(tx, &reply)).await {
                Ok(result) => result?,
                Err(_) => {
                    log::warning!("usb: host is not reading, reply dropped");
                    writable = false;
                }
            }
        }
        if reply.is_final() {
            return Ok(());
        }
    }
}

/// Writes an unsolicited notice as `[text]`: brackets tell notices from
/// replies (which are data lines, `ok` or `error: …`).
async fn write_notice<W: Write>(tx: &mut W, notice: &ReplyText) -> Result<(), W::Error> {
    let write = async {
        tx.write_all(b"[").await?;
        tx.write_all(notice.as_bytes()).await?;
        tx.write_all(b"]\r\n").await?;
        tx.flush().await
    };
    match with_timeout(WRITE_TIMEOUT, write).await {
        Ok(result) => result,
        Err(_) => Ok(()),
    }
}

/// Writes one reply item as a CRLF-terminated line.
async fn write_reply<W: Write>(tx: &mut W, reply: &Reply) -> Result<(), W::Error> {
    match reply {
        Reply::Data(text) => tx.write_all(text.as_bytes()).await?,
        Reply::Ok => tx.write_all(b"ok").await?,
        Reply::Error(text) => {
            tx.write_all(b"error: ").await?;
            tx.write_all(text.as_bytes()).await?;
        }
    }
    tx.write_all(b"\r\n").await?;
    tx.flush().await
}
