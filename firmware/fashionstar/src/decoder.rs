//! Streaming frame decoder, shared by both directions: accepts bytes in any
//! chunking, resynchronises on the header after garbage, checks the
//! declared length against the code and the checksum, and keeps at most
//! one frame ([`MAX_FRAME_LEN`] bytes) buffered.

use core::marker::PhantomData;

use crate::wire::checksum;
use crate::{
    DecodeError, FRAME_OVERHEAD, MAX_FRAME_LEN, MAX_PAYLOAD_LEN, Message, Request, Response,
};

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
mod tests;
