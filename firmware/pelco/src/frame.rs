//! The two frame layouts and their checksums.

/// Which PELCO dialect a frame uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Protocol {
    /// PELCO-D: 7 bytes, sync 0xFF, additive checksum.
    D,
    /// PELCO-P: 8 bytes, STX 0xA0 … ETX 0xAF, XOR checksum.
    P,
}

impl Protocol {
    /// The byte a frame starts with.
    pub const fn sync(self) -> u8 {
        match self {
            Protocol::D => 0xFF,
            Protocol::P => 0xA0,
        }
    }

    /// Frame length, bytes.
    pub const fn frame_len(self) -> usize {
        match self {
            Protocol::D => 7,
            Protocol::P => 8,
        }
    }

    /// The protocol whose frames start with `byte`.
    pub const fn from_sync(byte: u8) -> Option<Self> {
        match byte {
            0xFF => Some(Protocol::D),
            0xA0 => Some(Protocol::P),
            _ => None,
        }
    }

    /// The address byte that reaches device `device` (1–255): PELCO-D
    /// sends the device number, PELCO-P numbers devices from 0 (device 1 is
    /// address byte 0).
    pub const fn wire_address(self, device: u8) -> u8 {
        match self {
            Protocol::D => device,
            Protocol::P => device.wrapping_sub(1),
        }
    }

    /// Name for logs and the console (`D` / `P`).
    pub const fn name(self) -> &'static str {
        match self {
            Protocol::D => "D",
            Protocol::P => "P",
        }
    }
}

/// PELCO-P's end-of-text byte (byte 6 of every frame).
pub const ETX: u8 = 0xAF;

/// Longest frame (PELCO-P), bytes.
pub const MAX_FRAME_LEN: usize = 8;

/// One frame: its dialect, address and the four command/data bytes
/// (PELCO-D cmd1, cmd2, data1, data2 = PELCO-P d1, d2, d3, d4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frame {
    /// Dialect.
    pub protocol: Protocol,
    /// Device address byte as sent.
    pub address: u8,
    /// cmd1, cmd2, data1, data2.
    pub bytes: [u8; 4],
}

/// An encoded frame: `len` bytes of `bytes` (7 for PELCO-D, 8 for
/// PELCO-P).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameBytes {
    bytes: [u8; MAX_FRAME_LEN],
    len: usize,
}

impl FrameBytes {
    /// The frame's bytes.
    pub fn as_slice(&self) -> &[u8] {
        self.bytes.get(..self.len).unwrap_or(&self.bytes)
    }
}

impl Frame {
    /// The frame's bytes on the wire, checksum included.
    pub fn encode(&self) -> FrameBytes {
        let [c1, c2, d1, d2] = self.bytes;
        let mut bytes = [0u8; MAX_FRAME_LEN];
        match self.protocol {
            Protocol::D => {
                bytes[..6].copy_from_slice(&[0xFF, self.address, c1, c2, d1, d2]);
                bytes[6] = d_sum(&bytes[1..6]);
            }
            Protocol::P => {
                bytes[..7].copy_from_slice(&[0xA0, self.address, c1, c2, d1, d2, ETX]);
                bytes[7] = p_xor(&bytes[..7]);
            }
        }
        FrameBytes {
            bytes,
            len: self.protocol.frame_len(),
        }
    }

    /// The frame in `raw` when it is a whole, well-formed frame of
    /// `raw`'s dialect (sync, length, ETX, checksum); `None` otherwise.
    pub fn parse(raw: &[u8]) -> Option<Frame> {
        let protocol = Protocol::from_sync(*raw.first()?)?;
        if raw.len() != protocol.frame_len() {
            return None;
        }
        let ok = match protocol {
            Protocol::D => raw.get(6) == Some(&d_sum(raw.get(1..6)?)),
            Protocol::P => raw.get(6) == Some(&ETX) && raw.get(7) == Some(&p_xor(raw.get(..7)?)),
        };
        let body: [u8; 5] = raw.get(1..6)?.try_into().ok()?;
        ok.then_some(Frame {
            protocol,
            address: body[0],
            bytes: [body[1], body[2], body[3], body[4]],
        })
    }
}

/// PELCO-D checksum: the sum of address, cmd1, cmd2, data1, data2 mod 256.
pub fn d_sum(body: &[u8]) -> u8 {
    body.iter().fold(0u8, |s, b| s.wrapping_add(*b))
}

/// PELCO-P checksum: the XOR of STX, address, d1..d4 and ETX.
pub fn p_xor(head: &[u8]) -> u8 {
    head.iter().fold(0u8, |s, b| s ^ b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pelco_d_pan_right_matches_the_published_example() {
        // Address 1, pan right at speed 0x20: FF 01 00 02 20 00 23.
        let f = Frame {
            protocol: Protocol::D,
            address: 1,
            bytes: [0x00, 0x02, 0x20, 0x00],
        };
        assert_eq!(
            f.encode().as_slice(),
            &[0xFF, 0x01, 0x00, 0x02, 0x20, 0x00, 0x23]
        );
        assert_eq!(Frame::parse(f.encode().as_slice()), Some(f));
    }

    #[test]
    fn pelco_p_frame_has_etx_and_xor() {
        let f = Frame {
            protocol: Protocol::P,
            address: 0,
            bytes: [0x00, 0x04, 0x20, 0x00],
        };
        let raw = f.encode();
        assert_eq!(
            raw.as_slice(),
            &[0xA0, 0x00, 0x00, 0x04, 0x20, 0x00, 0xAF, 0x2B]
        );
        assert_eq!(Frame::parse(raw.as_slice()), Some(f));
        let mut bad = [0u8; 8];
        bad.copy_from_slice(raw.as_slice());
        bad[6] = 0xAE;
        assert_eq!(Frame::parse(&bad), None);
    }
}
