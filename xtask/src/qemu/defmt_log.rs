//! laser-app's logs as defmt from the board's UART3 (an image built with
//! `qemu-m4`'s `defmt-log` feature): rzcobs-framed defmt frames decoded
//! with the defmt tooling (`defmt-decoder`, the decoder probe-rs uses)
//! against the image's ELF, so each line reads as under probe-rs:
//! `<s.µs> INFO message`. An image without defmt has no table: nothing
//! arrives on UART3 and the reader just drains it.

use std::io::Read;
use std::os::unix::net::UnixStream;

use defmt_decoder::{DecodeError, Table};

use super::board_log::SharedLog;

/// Reads UART3 until QEMU closes it, decoding every frame into
/// `log.defmt_lines` (and on stderr when `echo`).
pub fn read_defmt(mut stream: UnixStream, elf: Vec<u8>, log: SharedLog, echo: bool) {
    let table = match Table::parse(&elf) {
        Ok(Some(table)) => table,
        Ok(None) => {
            let mut sink = [0u8; 256];
            while matches!(stream.read(&mut sink), Ok(n) if n > 0) {}
            return;
        }
        Err(e) => {
            eprintln!("xtask qemu: the image's defmt table is unreadable: {e:#}");
            return;
        }
    };
    let mut decoder = table.new_stream_decoder();
    let mut chunk = [0u8; 512];
    loop {
        let n = match stream.read(&mut chunk) {
            Ok(0) | Err(_) => return,
            Ok(n) => n,
        };
        decoder.received(&chunk[..n]);
        loop {
            let line = match decoder.decode() {
                Ok(frame) => frame.display(false).to_string(),
                Err(DecodeError::UnexpectedEof) => break,
                Err(DecodeError::Malformed) => "(malformed defmt frame)".to_owned(),
            };
            if echo {
                eprintln!("[board] {line}");
            }
            if let Ok(mut log) = log.0.lock() {
                log.defmt_lines.push(line);
            }
        }
    }
}
