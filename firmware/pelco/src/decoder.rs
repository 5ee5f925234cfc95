//! The streaming decoder: bytes in as they arrive, frames for this device
//! out, everything else counted.

use crate::frame::{Frame, MAX_FRAME_LEN, Protocol};

/// What the decoder has seen since it was created (wrapping counters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Counters {
    /// Well-formed frames for this device.
    pub frames: u32,
    /// Frame-length runs from a sync byte whose checksum (or PELCO-P ETX)
    /// did not hold.
    pub bad_checksums: u32,
    /// Well-formed frames for other devices on the bus (ignored).
    pub other_addresses: u32,
    /// Bytes dropped outside any frame (garbage before a sync byte, and
    /// the sync byte of each bad frame).
    pub discarded_bytes: u32,
}

/// Streaming PELCO-D / PELCO-P decoder for device `address` (1–255).
///
/// Bytes are buffered from a sync byte (0xFF or 0xA0) until a frame's
/// length of that dialect is in; a well-formed frame is handed out (or
/// counted as another device's), a bad one is counted and the search for
/// the next sync byte starts at the byte after its sync byte, so a frame
/// that follows garbage or a torn frame is still found. At most one frame
/// is ever buffered; no input panics.
#[derive(Debug, Clone)]
pub struct Decoder {
    address: u8,
    buf: [u8; MAX_FRAME_LEN],
    len: usize,
    counters: Counters,
}

impl Decoder {
    /// A decoder for device `address` with nothing buffered.
    pub const fn new(address: u8) -> Self {
        Self {
            address,
            buf: [0; MAX_FRAME_LEN],
            len: 0,
            counters: Counters {
                frames: 0,
                bad_checksums: 0,
                other_addresses: 0,
                discarded_bytes: 0,
            },
        }
    }

    /// The device address frames must carry.
    pub fn address(&self) -> u8 {
        self.address
    }

    /// Answers device `address` from now on (the buffer is kept).
    pub fn set_address(&mut self, address: u8) {
        self.address = address;
    }

    /// The counts so far.
    pub fn counters(&self) -> Counters {
        self.counters
    }

    /// Bytes buffered (0 when between frames).
    pub fn buffered(&self) -> usize {
        self.len
    }

    /// Takes one byte; returns the frame it completes, if that frame is
    /// well-formed and for this device.
    pub fn feed(&mut self, byte: u8) -> Option<Frame> {
        if self.len == 0 && Protocol::from_sync(byte).is_none() {
            self.counters.discarded_bytes = self.counters.discarded_bytes.wrapping_add(1);
            return None;
        }
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = byte;
            self.len += 1;
        }
        // A run as long as its dialect's frame is judged at once; after a
        // bad one, the run found behind it may already be whole (a stray
        // PELCO-P sync byte just before a PELCO-D frame).
        loop {
            let protocol = Protocol::from_sync(*self.buf.first()?)?;
            if self.len < protocol.frame_len() {
                return None;
            }
            match Frame::parse(self.buf.get(..protocol.frame_len()).unwrap_or(&[])) {
                Some(frame) => {
                    self.len = 0;
                    if frame.address == protocol.wire_address(self.address) {
                        self.counters.frames = self.counters.frames.wrapping_add(1);
                        return Some(frame);
                    }
                    self.counters.other_addresses = self.counters.other_addresses.wrapping_add(1);
                    return None;
                }
                None => {
                    self.counters.bad_checksums = self.counters.bad_checksums.wrapping_add(1);
                    self.resync();
                    if self.len == 0 {
                        return None;
                    }
                }
            }
        }
    }

    /// Drops the buffered run's sync byte and everything up to the next
    /// sync byte in the buffer (which then starts the next frame).
    fn resync(&mut self) {
        let rest = self.buf.get(1..self.len).unwrap_or(&[]);
        let skip = rest
            .iter()
            .position(|b| Protocol::from_sync(*b).is_some())
            .map_or(self.len, |i| i + 1);
        self.buf.copy_within(skip..self.len, 0);
        self.len -= skip;
        self.counters.discarded_bytes = self.counters.discarded_bytes.wrapping_add(skip as u32);
    }

    /// Feeds `bytes` in order, calling `on_frame` with each frame for this
    /// device.
    pub fn decode(&mut self, bytes: &[u8], mut on_frame: impl FnMut(Frame)) {
        for &b in bytes {
            if let Some(frame) = self.feed(b) {
                on_frame(frame);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::vec::Vec;

    use super::*;
    use crate::Command;

    fn frames(d: &mut Decoder, bytes: &[u8]) -> usize {
        let mut n = 0;
        d.decode(bytes, |_| n += 1);
        n
    }

    #[test]
    fn frame_after_garbage_and_a_torn_frame_is_found() {
        let mut d = Decoder::new(1);
        let good = Command::QueryPan.frame(Protocol::D, 1).encode();
        assert_eq!(frames(&mut d, &[0x12, 0x34, 0xFF, 0x01, 0x00]), 0);
        assert_eq!(frames(&mut d, good.as_slice()), 1);
        let c = d.counters();
        assert_eq!((c.frames, c.bad_checksums), (1, 1));
        assert_eq!(d.buffered(), 0);
    }

    #[test]
    fn bad_checksum_and_other_address_are_counted_not_delivered() {
        let mut d = Decoder::new(1);
        let mut bad = [0u8; 7];
        bad.copy_from_slice(Command::QueryTilt.frame(Protocol::D, 1).encode().as_slice());
        bad[6] ^= 1;
        assert_eq!(frames(&mut d, &bad), 0);
        let other = Command::QueryTilt.frame(Protocol::D, 2).encode();
        assert_eq!(frames(&mut d, other.as_slice()), 0);
        let c = d.counters();
        assert_eq!((c.frames, c.bad_checksums, c.other_addresses), (0, 1, 1));
    }

    #[test]
    fn a_stray_pelco_p_sync_before_a_pelco_d_frame_does_not_hide_it() {
        // A0 then a whole PELCO-D frame: the 8-byte PELCO-P run is bad,
        // the PELCO-D frame behind its sync byte is whole at once.
        let mut d = Decoder::new(1);
        let good = Command::QueryPan.frame(Protocol::D, 1);
        let mut got = Vec::new();
        d.decode(&[0xA0], |f| got.push(f));
        d.decode(good.encode().as_slice(), |f| got.push(f));
        assert_eq!(got, std::vec![good]);
        let c = d.counters();
        assert_eq!((c.frames, c.bad_checksums, c.discarded_bytes), (1, 1, 1));
        assert_eq!(d.buffered(), 0);
    }

    #[test]
    fn pelco_p_numbers_devices_from_zero() {
        let mut d = Decoder::new(1);
        let to_device_1 = Command::QueryPan.frame(Protocol::P, 0).encode();
        assert_eq!(frames(&mut d, to_device_1.as_slice()), 1);
        let to_device_2 = Command::QueryPan.frame(Protocol::P, 1).encode();
        assert_eq!(frames(&mut d, to_device_2.as_slice()), 0);
    }

    #[test]
    fn turbo_speed_0xff_inside_a_frame_is_data() {
        // FF 01 00 04 FF 00 sum: pan left at turbo.
        let mut d = Decoder::new(1);
        let f = Command::from_bytes([0, 0x04, 0xFF, 0]).frame(Protocol::D, 1);
        let mut got = None;
        d.decode(f.encode().as_slice(), |fr| got = Some(fr));
        assert_eq!(got, Some(f));
    }
}
