//! The PELCO port: PELCO-D / PELCO-P frames from a CCTV keyboard, DVR or
//! PTZ software (RS-485) as another way to command the active actuator.
//!
//! * [`task`]: the port's task body, generic over `embedded-io-async`
//!   `Read`/`Write`: decodes frames for this device ([`::pelco::Decoder`]),
//!   hands them to the session, sends what it asks through the console's
//!   command channel (quietly: see [`crate::outbound::Outbound::begin_quiet_command`])
//!   and writes the position replies;
//! * [`session`]: frames as the product's own commands (jogs, `goto`,
//!   `laser`, `stop`), presets, position replies;
//! * [`speed`]: the speed table; [`sight`]: angles of a board point.
//!
//! `pelco status` on the console reads [`PelcoStatus`].
//! See `docs/pelco.md`.

pub mod session;
pub mod sight;
pub mod speed;
pub mod task;

use core::fmt;
use core::sync::atomic::{AtomicU8, AtomicU32, Ordering::Relaxed};

use ::pelco::{Counters, Frame, Protocol};

pub use self::session::{Request, Session, View};
pub use self::task::PelcoTask;

/// What the PELCO port has seen, for `pelco status` (written by the port
/// task, read by the console).
pub struct PelcoStatus {
    frames: AtomicU32,
    bad_checksums: AtomicU32,
    other_addresses: AtomicU32,
    discarded_bytes: AtomicU32,
    /// Device address answered (0: no port task runs).
    address: AtomicU8,
    /// Dialect of the last frame: 0 none, 1 PELCO-D, 2 PELCO-P.
    last_protocol: AtomicU8,
    /// cmd1, cmd2, data1, data2 of the last frame.
    last_bytes: AtomicU32,
}

impl PelcoStatus {
    /// Nothing seen, no port.
    pub const fn new() -> Self {
        Self {
            frames: AtomicU32::new(0),
            bad_checksums: AtomicU32::new(0),
            other_addresses: AtomicU32::new(0),
            discarded_bytes: AtomicU32::new(0),
            address: AtomicU8::new(0),
            last_protocol: AtomicU8::new(0),
            last_bytes: AtomicU32::new(0),
        }
    }

    /// The port answers device `address`.
    pub fn set_address(&self, address: u8) {
        self.address.store(address, Relaxed);
    }

    /// The decoder's counts.
    pub fn publish(&self, c: Counters) {
        self.frames.store(c.frames, Relaxed);
        self.bad_checksums.store(c.bad_checksums, Relaxed);
        self.other_addresses.store(c.other_addresses, Relaxed);
        self.discarded_bytes.store(c.discarded_bytes, Relaxed);
    }

    /// The last frame for this device.
    pub fn note_frame(&self, frame: &Frame) {
        self.last_bytes
            .store(u32::from_be_bytes(frame.bytes), Relaxed);
        let code = match frame.protocol {
            Protocol::D => 1,
            Protocol::P => 2,
        };
        self.last_protocol.store(code, Relaxed);
    }

    /// The counts so far.
    pub fn counters(&self) -> Counters {
        Counters {
            frames: self.frames.load(Relaxed),
            bad_checksums: self.bad_checksums.load(Relaxed),
            other_addresses: self.other_addresses.load(Relaxed),
            discarded_bytes: self.discarded_bytes.load(Relaxed),
        }
    }

    /// The last frame for this device (its address is this device's).
    pub fn last_frame(&self) -> Option<Frame> {
        let protocol = match self.last_protocol.load(Relaxed) {
            1 => Protocol::D,
            2 => Protocol::P,
            _ => return None,
        };
        let address = protocol.wire_address(self.address.load(Relaxed));
        Some(Frame {
            protocol,
            address,
            bytes: self.last_bytes.load(Relaxed).to_be_bytes(),
        })
    }

    /// The `pelco status` lines, one per call of `line`.
    pub fn report(&self, mut line: impl FnMut(fmt::Arguments<'_>)) {
        let address = self.address.load(Relaxed);
        if address == 0 {
            return line(format_args!("pelco: no port on this board"));
        }
        let c = self.counters();
        line(format_args!("pelco: address {address}"));
        line(format_args!(
            "frames {} bad_checksums {} other_addresses {} discarded_bytes {}",
            c.frames, c.bad_checksums, c.other_addresses, c.discarded_bytes
        ));
        match self.last_frame() {
            Some(f) => {
                let [c1, c2, d1, d2] = f.bytes;
                line(format_args!(
                    "last: PELCO-{} {} ({c1:02X} {c2:02X} {d1:02X} {d2:02X})",
                    f.protocol.name(),
                    ::pelco::Command::of(&f).name()
                ))
            }
            None => line(format_args!("last: none")),
        }
    }
}

impl Default for PelcoStatus {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests;
