//! Streaming frame decoder, shared by both directions: accepts bytes in any
//! chunking, resynchronises on the header after garbage, checks the
//! declared length against the code and the checksum, and keeps at most
//! one frame ([`MAX_FRAME_LEN`] bytes) buffered.

use core::marker::PhantomData;

use super::wire::checksum;
use super::{
    DecodeError, EncodeError, FRAME_OVERHEAD, MAX_FRAME_LEN, MAX_PAYLOAD_LEN, Request, Response,
};

/// A frame type of one direction: its header, the payload lengths of each
/// code, and its parser and encoder.
pub trait Message: Sized {
    /// The two header bytes.
    const HEADER: [u8; 2];
    /// Allowed payload length range (inclusive, bytes) for `code`, or
    /// `None` for a code this codec does not model.
    fn payload_len(code: u8) -> Option<(usize, usize)>;
    /// Parses the payload of an intact frame (checksum already verified).
    fn parse(code: u8, payload: &[u8]) -> Result<Self, DecodeError>;
    /// Writes the frame into `out`; returns its length in bytes.
    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError>;
}

/// Streaming decoder of frames of type `M`.
///
/// Typical use: `for event in decoder.decode(&chunk) { … }`, or byte by
/// byte with [`StreamDecoder::feed`]. Errors are reported as events; the
/// decoder resynchronises by itself.
pub struct StreamDecoder<M> {
    buf: [u8; MAX_FRAME_LEN],
    len: usize,
    _message: PhantomData<fn() -> M>,
}

/// Decodes response frames (firmware side).
pub type ResponseDecoder = StreamDecoder<Response>;
/// Decodes request frames (simulated servo side).
pub type RequestDecoder = StreamDecoder<Request>;

impl<M: Message> Default for StreamDecoder<M> {
    fn default() -> Self {
        Self::new()
    }
}

impl<M: Message> StreamDecoder<M> {
    /// An empty decoder.
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_FRAME_LEN],
            len: 0,
            _message: PhantomData,
        }
    }

    /// Adds one byte and returns the first event it completes, if any.
    ///
    /// After an error the bytes behind the false header are rescanned and
    /// may already hold further events (e.g. a real frame hidden inside a
    /// false one): call [`StreamDecoder::poll`] until it returns `None` to
    /// get them now, or they come out of the following calls. [`decode`]
    /// does this for a whole chunk.
    ///
    /// [`decode`]: StreamDecoder::decode
    pub fn feed(&mut self, byte: u8) -> Option<Result<M, DecodeError>> {
        self.push(byte);
        self.poll()
    }

    /// Adds one byte without decoding. Call [`StreamDecoder::poll`] after
    /// each push; if the buffer is full anyway, the oldest byte is dropped.
    pub fn push(&mut self, byte: u8) {
        if self.len >= MAX_FRAME_LEN {
            self.consume(1);
        }
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = byte;
            self.len += 1;
        }
    }

    /// The next event from the buffered bytes, or `None` when more bytes
    /// are needed.
    pub fn poll(&mut self) -> Option<Result<M, DecodeError>> {
        self.skip_to_header();
        let &[_, _, code, len] = self.filled().first_chunk::<4>()?;
        let declared = usize::from(len);
        let known = M::payload_len(code);
        let fits = match known {
            Some((lo, hi)) => (lo..=hi).contains(&declared),
            None => declared <= MAX_PAYLOAD_LEN,
        };
        if !fits {
            self.consume(2);
            return Some(Err(DecodeError::BadLength { code, len }));
        }
        let total = declared + FRAME_OVERHEAD;
        let (&received, body) = self.filled().get(..total)?.split_last()?;
        let computed = checksum(body);
        if computed != received {
            self.consume(2);
            return Some(Err(DecodeError::BadChecksum {
                code,
                computed,
                received,
            }));
        }
        let result = match (known, body.get(4..)) {
            (Some(_), Some(payload)) => M::parse(code, payload),
            _ => Err(DecodeError::UnknownCode { code }),
        };
        self.consume(total);
        Some(result)
    }

    /// Decodes a chunk: an iterator over every event the bytes complete
    /// (including events left over from earlier bytes).
    pub fn decode<'a>(&'a mut self, bytes: &'a [u8]) -> Decoded<'a, M> {
        Decoded {
            decoder: self,
            bytes: bytes.iter(),
        }
    }

    /// Bytes held back as the start of a possible frame (never more than
    /// [`MAX_FRAME_LEN`]).
    pub fn buffered(&self) -> usize {
        self.len
    }

    /// Forgets every buffered byte.
    pub fn reset(&mut self) {
        self.len = 0;
    }

    fn filled(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or(&[])
    }

    /// Drops the first `n` buffered bytes.
    fn consume(&mut self, n: usize) {
        let n = n.min(self.len);
        if let Some(filled) = self.buf.get_mut(..self.len) {
            filled.rotate_left(n);
        }
        self.len -= n;
    }

    /// Drops bytes until the buffer starts with the header (or with its
    /// first byte as the last byte buffered).
    fn skip_to_header(&mut self) {
        let [h0, h1] = M::HEADER;
        let filled = self.filled();
        let start = (0..filled.len())
            .find(|&i| filled.get(i) == Some(&h0) && filled.get(i + 1).is_none_or(|b| *b == h1))
            .unwrap_or(filled.len());
        self.consume(start);
    }
}

/// Iterator over the events decoded from a chunk of bytes; see
/// [`StreamDecoder::decode`].
pub struct Decoded<'a, M> {
    decoder: &'a mut StreamDecoder<M>,
    bytes: core::slice::Iter<'a, u8>,
}

impl<M: Message> Iterator for Decoded<'_, M> {
    type Item = Result<M, DecodeError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(event) = self.decoder.poll() {
                return Some(event);
            }
            let byte = self.bytes.next()?;
            self.decoder.push(*byte);
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::vec::Vec;

    use super::*;
    use crate::servo::protocol::SetAngle;

    fn all<M: Message>(d: &mut StreamDecoder<M>, bytes: &[u8]) -> Vec<Result<M, DecodeError>> {
        d.decode(bytes).collect()
    }

    const PING0: [u8; 6] = [0x05, 0x1C, 0x01, 0x01, 0x00, 0x23];
    const ANGLE1: [u8; 8] = [0x05, 0x1C, 0x0A, 0x03, 0x01, 0x85, 0xFF, 0xB3];

    #[test]
    fn byte_by_byte() {
        let mut d = ResponseDecoder::new();
        let mut out = Vec::new();
        for &b in PING0.iter().chain(&ANGLE1) {
            if let Some(ev) = d.feed(b) {
                out.push(ev);
            }
        }
        assert_eq!(
            out,
            [
                Ok(Response::Ping { id: 0 }),
                Ok(Response::Angle {
                    id: 1,
                    angle_tenths_deg: -123
                })
            ]
        );
        assert_eq!(d.buffered(), 0);
    }

    #[test]
    fn garbage_before_between_and_split_header() {
        let mut d = ResponseDecoder::new();
        assert_eq!(all(&mut d, &[0x00, 0xFF, 0x05, 0x05]), []);
        // The last 0x05 may start a header: it is kept.
        assert_eq!(d.buffered(), 1);
        let mut rest = PING0[1..].to_vec();
        rest.extend([0x1C, 0x77]);
        rest.extend(ANGLE1);
        let out = all(&mut d, &rest);
        assert_eq!(out.len(), 2);
        assert_eq!(out[0], Ok(Response::Ping { id: 0 }));
        assert!(out[1].is_ok());
    }

    #[test]
    fn bad_checksum_then_rescan_finds_hidden_frame() {
        // A false header announcing a 16-byte monitor payload swallows a
        // real ping; the false frame fails its checksum, and the rescan from
        // the byte after the false header finds the ping.
        let mut bytes = std::vec![0x05, 0x1C, 0x16, 0x10, 0x01];
        bytes.extend(PING0);
        bytes.extend([0x00; 11]);
        let mut d = ResponseDecoder::new();
        let out = all(&mut d, &bytes);
        assert!(matches!(
            out[0],
            Err(DecodeError::BadChecksum { code: 22, .. })
        ));
        assert_eq!(out[1], Ok(Response::Ping { id: 0 }));
        assert_eq!(out.len(), 2);
    }

    #[test]
    fn feed_leaves_hidden_frame_for_poll() {
        let mut bytes = std::vec![0x05, 0x1C, 0x16, 0x10];
        bytes.extend(PING0);
        bytes.extend([0x00; 11]);
        let mut d = ResponseDecoder::new();
        let mut events = Vec::new();
        for &b in &bytes {
            if let Some(ev) = d.feed(b) {
                events.push(ev);
                while let Some(ev) = d.poll() {
                    events.push(ev);
                }
            }
        }
        assert!(events[0].is_err());
        assert_eq!(events[1], Ok(Response::Ping { id: 0 }));
    }

    #[test]
    fn bad_length_is_reported_at_the_length_byte() {
        let mut d = ResponseDecoder::new();
        assert_eq!(all(&mut d, &[0x05, 0x1C, 0x0A]), []);
        assert_eq!(
            d.feed(0x02),
            Some(Err(DecodeError::BadLength { code: 10, len: 2 }))
        );
        // Extended-length marker 0xFF.
        assert_eq!(
            all(&mut d, &[0x05, 0x1C, 0x19, 0xFF]),
            [Err(DecodeError::BadLength {
                code: 25,
                len: 0xFF
            })]
        );
        assert_eq!(all(&mut d, &PING0), [Ok(Response::Ping { id: 0 })]);
    }

    #[test]
    fn unknown_code_frame_is_skipped_whole() {
        // A write-data response (code 4: id, address, result) is intact but
        // not modelled: 05+1C+04+03+00+21+01 = 0x4A.
        let mut bytes = std::vec![0x05, 0x1C, 0x04, 0x03, 0x00, 0x21, 0x01, 0x4A];
        bytes.extend(PING0);
        let mut d = ResponseDecoder::new();
        assert_eq!(
            all(&mut d, &bytes),
            [
                Err(DecodeError::UnknownCode { code: 4 }),
                Ok(Response::Ping { id: 0 })
            ]
        );
    }

    #[test]
    fn requests_decode_too_and_reset_forgets() {
        let r = Request::sync_set_angle_pair(
            SetAngle {
                id: 0,
                angle_tenths_deg: 100,
                interval_ms: 300,
                power_mw: 0,
            },
            SetAngle {
                id: 1,
                angle_tenths_deg: -200,
                interval_ms: 300,
                power_mw: 0,
            },
        );
        let f = r.to_frame().unwrap();
        let mut d = RequestDecoder::new();
        assert_eq!(all(&mut d, &f[..10]), []);
        d.reset();
        assert_eq!(all(&mut d, &f[10..]), []);
        assert_eq!(all(&mut d, &f), [Ok(r)]);
        // Response bytes on the line are ignored by the request decoder.
        assert_eq!(all(&mut d, &PING0), []);
    }

    #[test]
    fn push_without_poll_stays_bounded() {
        let mut d = ResponseDecoder::new();
        for _ in 0..1000 {
            d.push(0x05);
        }
        assert!(d.buffered() <= MAX_FRAME_LEN);
        let _ = all(&mut d, &[]);
    }
}
