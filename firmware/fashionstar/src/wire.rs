//! Byte-level helpers: checksum, little-endian payload writer and reader,
//! and framing of a payload.

use heapless::Vec;

use crate::{EncodeError, FRAME_OVERHEAD, MAX_PAYLOAD_LEN};

/// A payload under construction.
pub(crate) type Payload = Vec<u8, MAX_PAYLOAD_LEN>;

/// Sum of `bytes` mod 256: the checksum of a frame is this over every byte
/// before it, header included (vendor SDK `RingBuffer_GetChecksum`).
pub fn checksum(bytes: &[u8]) -> u8 {
    bytes.iter().fold(0u8, |sum, b| sum.wrapping_add(*b))
}

/// Appends little-endian fields to a payload ([`crate::Message::write_payload`]).
/// Every message type has a payload of at most [`MAX_PAYLOAD_LEN`] bytes by
/// construction; a write past the end is recorded and turned into an
/// [`EncodeError`] when the frame is built, rather than panicking.
pub struct PayloadWriter {
    payload: Payload,
    overflow: bool,
}

impl PayloadWriter {
    pub(crate) const fn new() -> Self {
        Self {
            payload: Vec::new(),
            overflow: false,
        }
    }

    /// Appends `bytes` as they are.
    pub fn bytes(&mut self, bytes: &[u8]) {
        if self.payload.extend_from_slice(bytes).is_err() {
            self.overflow = true;
        }
    }

    /// Appends one byte.
    pub fn u8(&mut self, v: u8) {
        self.bytes(&[v]);
    }

    /// Appends a little-endian `u16`.
    pub fn u16(&mut self, v: u16) {
        self.bytes(&v.to_le_bytes());
    }

    /// Appends a little-endian `i16`.
    pub fn i16(&mut self, v: i16) {
        self.bytes(&v.to_le_bytes());
    }

    /// Appends a little-endian `i32`.
    pub fn i32(&mut self, v: i32) {
        self.bytes(&v.to_le_bytes());
    }

    /// The payload, or the frame length that would have been needed.
    pub(crate) fn finish(self) -> Result<Payload, EncodeError> {
        if self.overflow {
            Err(EncodeError::BufferTooSmall {
                needed: MAX_PAYLOAD_LEN + FRAME_OVERHEAD + 1,
            })
        } else {
            Ok(self.payload)
        }
    }
}

/// Reads little-endian fields from a payload; `None` past the end.
pub(crate) struct Reader<'a> {
    rest: &'a [u8],
}

impl<'a> Reader<'a> {
    pub(crate) const fn new(payload: &'a [u8]) -> Self {
        Self { rest: payload }
    }

    pub(crate) fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (head, rest) = self.rest.split_first_chunk::<N>()?;
        self.rest = rest;
        Some(*head)
    }

    pub(crate) fn u8(&mut self) -> Option<u8> {
        self.take::<1>().map(|[b]| b)
    }

    pub(crate) fn u16(&mut self) -> Option<u16> {
        self.take().map(u16::from_le_bytes)
    }

    pub(crate) fn i16(&mut self) -> Option<i16> {
        self.take().map(i16::from_le_bytes)
    }

    pub(crate) fn i32(&mut self) -> Option<i32> {
        self.take().map(i32::from_le_bytes)
    }

    /// The bytes not read yet.
    pub(crate) fn rest(&self) -> &'a [u8] {
        self.rest
    }

    /// `Some(())` when every byte has been read.
    pub(crate) fn end(&self) -> Option<()> {
        self.rest.is_empty().then_some(())
    }
}

/// Writes `header, code, len, payload, checksum` into `out`; returns the
/// frame length.
pub(crate) fn write_frame(
    header: [u8; 2],
    code: u8,
    payload: &[u8],
    out: &mut [u8],
) -> Result<usize, EncodeError> {
    let needed = payload.len() + FRAME_OVERHEAD;
    let too_small = EncodeError::BufferTooSmall { needed };
    // Payloads are at most MAX_PAYLOAD_LEN (< 0xFF) by construction; the
    // check keeps a longer one from being framed with a wrong length byte.
    let len = u8::try_from(payload.len())
        .ok()
        .filter(|len| usize::from(*len) <= MAX_PAYLOAD_LEN)
        .ok_or(too_small)?;
    let frame = out.get_mut(..needed).ok_or(too_small)?;
    let code_len = [code, len];
    let bytes = header.iter().chain(&code_len).chain(payload);
    let mut sum = 0u8;
    for (slot, byte) in frame.iter_mut().zip(bytes) {
        *slot = *byte;
        sum = sum.wrapping_add(*byte);
    }
    if let Some(last) = frame.last_mut() {
        *last = sum;
    }
    Ok(needed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checksum_wraps() {
        assert_eq!(checksum(&[]), 0);
        assert_eq!(checksum(&[0xFF, 0x02]), 0x01);
        assert_eq!(checksum(&[0x12, 0x4C, 0x01, 0x01, 0x00]), 0x60);
    }

    #[test]
    fn frame_into_short_buffer_is_an_error() {
        let mut out = [0u8; 5];
        assert_eq!(
            write_frame([0x12, 0x4C], 1, &[0], &mut out),
            Err(EncodeError::BufferTooSmall { needed: 6 })
        );
        let mut out = [0u8; 6];
        assert_eq!(write_frame([0x12, 0x4C], 1, &[0], &mut out), Ok(6));
        assert_eq!(out, [0x12, 0x4C, 0x01, 0x01, 0x00, 0x60]);
    }

    #[test]
    fn reader_stops_at_the_end() {
        let mut r = Reader::new(&[1, 0x34, 0x12, 0xFF]);
        assert_eq!(r.u8(), Some(1));
        assert_eq!(r.u16(), Some(0x1234));
        assert_eq!(r.i16(), None);
        assert_eq!(r.rest(), &[0xFF]);
        assert_eq!(r.u8(), Some(0xFF));
        assert_eq!(r.end(), Some(()));
        assert_eq!(r.i32(), None);
    }

    #[test]
    fn writer_overflow_is_an_error() {
        let mut w = PayloadWriter::new();
        w.bytes(&[0; MAX_PAYLOAD_LEN]);
        assert!(w.finish().is_ok());
        let mut w = PayloadWriter::new();
        w.bytes(&[0; MAX_PAYLOAD_LEN]);
        w.u8(1);
        assert!(w.finish().is_err());
    }
}
