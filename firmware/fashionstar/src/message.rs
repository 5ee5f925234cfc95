//! [`Message`]: a frame type of one direction. A message says what the
//! protocol leaves to it (its header, its code, how its payload is laid
//! out and parsed); the framing around the payload (length byte, checksum)
//! is written once here for every message.

use heapless::Vec;

use crate::wire::{Payload, PayloadWriter, write_frame};
use crate::{DecodeError, EncodeError, FRAME_OVERHEAD, MAX_FRAME_LEN};

/// One whole frame, bytes (at most [`MAX_FRAME_LEN`]).
pub type Frame = Vec<u8, MAX_FRAME_LEN>;

/// A frame type of one direction ([`crate::Request`]: controller → servo,
/// [`crate::Response`]: servo → controller).
pub trait Message: Sized {
    /// The two header bytes.
    const HEADER: [u8; 2];

    /// Command code of the frame (the byte after the header).
    fn code(&self) -> u8;

    /// Appends the payload (the bytes between the length byte and the
    /// checksum).
    fn write_payload(&self, w: &mut PayloadWriter);

    /// Allowed payload length range (inclusive, bytes) for `code`, or
    /// `None` for a code this codec does not model.
    fn payload_len(code: u8) -> Option<(usize, usize)>;

    /// Parses the payload of an intact frame (checksum already verified).
    fn parse(code: u8, payload: &[u8]) -> Result<Self, DecodeError>;

    /// Frame length on the wire, bytes.
    fn encoded_len(&self) -> usize {
        payload(self).map_or(MAX_FRAME_LEN, |p| p.len() + FRAME_OVERHEAD)
    }

    /// Writes the frame into `out`; returns its length in bytes (at most
    /// [`MAX_FRAME_LEN`]).
    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        write_frame(Self::HEADER, self.code(), &payload(self)?, out)
    }

    /// The frame as a vector.
    fn to_frame(&self) -> Result<Frame, EncodeError> {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let len = self.encode(&mut buf)?;
        Vec::from_slice(buf.get(..len).unwrap_or(&[]))
            .map_err(|_| EncodeError::BufferTooSmall { needed: len })
    }
}

/// The payload of `message`, or the error of one that overflowed.
fn payload<M: Message>(message: &M) -> Result<Payload, EncodeError> {
    let mut w = PayloadWriter::new();
    message.write_payload(&mut w);
    w.finish()
}
