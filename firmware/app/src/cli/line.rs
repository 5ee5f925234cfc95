//! Line assembly for the USB command line: bytes in, complete lines out.
//!
//! * A line ends at CR, LF or CRLF (a CR followed by LF counts once, even when
//!   the two bytes arrive in different USB packets).
//! * Backspace (0x08) and DEL (0x7F) remove the previous byte, so typing in a
//!   terminal with local echo works.
//! * A line longer than [`MAX_LINE_LEN`] bytes is discarded up to its
//!   terminator and reported once as [`LineError::TooLong`]; memory use is
//!   fixed whatever arrives.
//! * Bytes that are not printable ASCII (or tab) make the line invalid; it is
//!   reported as [`LineError::InvalidByte`] when it ends.

use core::fmt;

/// Longest accepted command line, bytes (excluding the terminator);
/// defined with the command channel, which carries lines of this size.
pub use crate::command::MAX_LINE_LEN;

/// A complete, printable-ASCII command line (terminator removed).
pub type Line = heapless::String<MAX_LINE_LEN>;

/// Why a line was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LineError {
    /// The line exceeded [`MAX_LINE_LEN`] bytes and was discarded.
    TooLong,
    /// The line held a byte that is neither printable ASCII nor tab (the
    /// first such byte is given).
    InvalidByte(u8),
}

impl fmt::Display for LineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LineError::TooLong => write!(f, "line too long (max {MAX_LINE_LEN} bytes)"),
            LineError::InvalidByte(b) => write!(f, "invalid byte 0x{b:02x} in line"),
        }
    }
}

/// Byte-at-a-time line assembler with a fixed buffer.
#[derive(Debug, Default)]
pub struct LineAssembler {
    buf: heapless::Vec<u8, MAX_LINE_LEN>,
    overflowed: bool,
    invalid: Option<u8>,
    previous_was_cr: bool,
    /// The first [`LONG_LINE_HEAD`] bytes of the last line that overflowed.
    long_line_head: heapless::Vec<u8, LONG_LINE_HEAD>,
}

/// Bytes kept from the start of a too-long line, enough to tell which
/// language it was in (grbl answers `error:11` to its own).
pub const LONG_LINE_HEAD: usize = 8;

impl LineAssembler {
    /// An empty assembler.
    pub const fn new() -> Self {
        Self {
            buf: heapless::Vec::new(),
            overflowed: false,
            invalid: None,
            previous_was_cr: false,
            long_line_head: heapless::Vec::new(),
        }
    }

    /// Feeds one byte; returns a line (or the reason it was rejected) when
    /// this byte terminates one.
    pub fn push(&mut self, byte: u8) -> Option<Result<Line, LineError>> {
        let after_cr = core::mem::replace(&mut self.previous_was_cr, byte == b'\r');
        match byte {
            b'\n' if after_cr => None,
            b'\r' | b'\n' => Some(self.finish()),
            0x08 | 0x7f => {
                if !self.overflowed {
                    self.buf.pop();
                }
                None
            }
            _ => {
                if !(byte == b'\t' || (0x20..0x7f).contains(&byte)) && self.invalid.is_none() {
                    self.invalid = Some(byte);
                }
                if !self.overflowed && self.buf.push(byte).is_err() {
                    self.overflowed = true;
                    self.long_line_head.clear();
                    let head = self.buf.get(..LONG_LINE_HEAD).unwrap_or(&[]);
                    let _ = self.long_line_head.extend_from_slice(head);
                    self.buf.clear();
                }
                None
            }
        }
    }

    /// The start of the last line rejected as [`LineError::TooLong`] (up to
    /// [`LONG_LINE_HEAD`] bytes; empty before any; non-ASCII bytes make it
    /// empty).
    pub fn long_line_head(&self) -> &str {
        core::str::from_utf8(&self.long_line_head).unwrap_or("")
    }

    /// Whether bytes of an unfinished line are pending.
    pub fn is_mid_line(&self) -> bool {
        !self.buf.is_empty() || self.overflowed || self.invalid.is_some()
    }

    fn finish(&mut self) -> Result<Line, LineError> {
        let overflowed = core::mem::take(&mut self.overflowed);
        let invalid = self.invalid.take();
        let bytes = core::mem::take(&mut self.buf);
        if overflowed {
            return Err(LineError::TooLong);
        }
        if let Some(b) = invalid {
            return Err(LineError::InvalidByte(b));
        }
        // Only printable ASCII and tab reach here, so this cannot fail; map
        // the impossible case to an error rather than panicking.
        Line::from_utf8(bytes).map_err(|_| LineError::InvalidByte(0))
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::string::{String, ToString};
    use std::vec::Vec;

    fn feed(asm: &mut LineAssembler, bytes: &[u8]) -> Vec<Result<String, LineError>> {
        bytes
            .iter()
            .filter_map(|&b| asm.push(b))
            .map(|r| r.map(|l| l.as_str().to_string()))
            .collect()
    }

    #[test]
    fn splits_on_cr_lf_and_crlf() {
        let mut asm = LineAssembler::new();
        let out = feed(&mut asm, b"help\rversion\nstatus\r\nx\n");
        assert_eq!(
            out,
            [
                Ok("help".to_string()),
                Ok("version".to_string()),
                Ok("status".to_string()),
                Ok("x".to_string())
            ]
        );
    }

    #[test]
    fn crlf_split_across_packets_is_one_terminator() {
        let mut asm = LineAssembler::new();
        assert_eq!(feed(&mut asm, b"help\r"), [Ok("help".to_string())]);
        assert_eq!(feed(&mut asm, b"\nstatus\n"), [Ok("status".to_string())]);
    }

    #[test]
    fn empty_lines_are_reported_as_empty() {
        let mut asm = LineAssembler::new();
        let out = feed(&mut asm, b"\n\n\r\r\n");
        assert_eq!(out.len(), 4, "LF, LF, CR, CR(LF) are four empty lines");
        assert!(out.iter().all(|l| l.as_deref() == Ok("")));
    }

    #[test]
    fn backspace_and_delete_edit_the_line() {
        let mut asm = LineAssembler::new();
        assert_eq!(feed(&mut asm, b"helx\x08p\r"), [Ok("help".to_string())]);
        assert_eq!(
            feed(&mut asm, b"\x7f\x7fok\x7f\x7f\x7fstop\n"),
            [Ok("stop".to_string())]
        );
    }

    #[test]
    fn exactly_max_length_is_accepted() {
        let mut asm = LineAssembler::new();
        let mut line = [b'a'; MAX_LINE_LEN].to_vec();
        line.push(b'\n');
        let out = feed(&mut asm, &line);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].as_ref().map(String::len), Ok(MAX_LINE_LEN));
    }

    #[test]
    fn ten_kilobytes_without_newline_is_discarded_once() {
        let mut asm = LineAssembler::new();
        let junk = [b'z'; 10_240];
        assert!(feed(&mut asm, &junk).is_empty());
        assert!(asm.is_mid_line());
        assert_eq!(feed(&mut asm, b"\n"), [Err(LineError::TooLong)]);
        assert_eq!(asm.long_line_head(), "zzzzzzzz");
        // The assembler is clean afterwards.
        assert!(!asm.is_mid_line());
        assert_eq!(feed(&mut asm, b"help\n"), [Ok("help".to_string())]);
    }

    #[test]
    fn binary_bytes_reject_the_line_and_name_the_byte() {
        let mut asm = LineAssembler::new();
        assert_eq!(
            feed(&mut asm, b"he\x00lp\n"),
            [Err(LineError::InvalidByte(0x00))]
        );
        assert_eq!(
            feed(&mut asm, &[0xff, 0xfe, b'\n', b'o', b'k', b'\n']),
            [Err(LineError::InvalidByte(0xff)), Ok("ok".to_string())]
        );
    }

    #[test]
    fn every_byte_value_in_any_order_never_panics_and_stays_bounded() {
        // Deterministic pseudo-random garbage, including terminators.
        let mut asm = LineAssembler::new();
        let mut x: u32 = 0x1234_5678;
        let mut lines = 0;
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            if let Some(r) = asm.push((x >> 24) as u8) {
                lines += 1;
                if let Ok(l) = r {
                    assert!(l.len() <= MAX_LINE_LEN);
                    assert!(l.bytes().all(|b| b == b'\t' || (0x20..0x7f).contains(&b)));
                }
            }
        }
        assert!(lines > 0);
    }

    #[test]
    fn error_messages_read_well() {
        assert_eq!(
            LineError::TooLong.to_string(),
            "line too long (max 128 bytes)"
        );
        assert_eq!(
            LineError::InvalidByte(0x1b).to_string(),
            "invalid byte 0x1b in line"
        );
    }
}
