//! PELCO-D and PELCO-P, the serial pan-tilt protocols of CCTV keyboards,
//! DVRs and PTZ software, without allocation:
//!
//! * [`Frame`]: one frame of either protocol with its address and its four
//!   command/data bytes, encoded byte-exactly ([`Frame::encode`]);
//! * [`Command`]: what a frame means (motion, presets, auxiliaries, reset,
//!   absolute positions, position queries and replies), and back
//!   ([`Command::frame`]);
//! * [`Decoder`]: a streaming decoder that takes bytes as they arrive,
//!   resynchronises on the next sync byte after garbage or a bad checksum,
//!   keeps the frames for its own address and counts the rest
//!   ([`Counters`]).
//!
//! PELCO-D: `FF addr cmd1 cmd2 data1 data2 sum`, the sum of addr, cmd1,
//! cmd2, data1 and data2 mod 256. PELCO-P: `A0 addr d1 d2 d3 d4 AF xor`,
//! the XOR of the seven bytes before it. Both carry the same four bytes
//! (PELCO-P's d1..d4 sit where PELCO-D's cmd1, cmd2, data1, data2 do), so
//! one [`Command`] table serves both.
#![no_std]

mod command;
mod decoder;
mod frame;

pub use command::{
    Command, Motion, PanDirection, TiltDirection, deg_to_hundredths, hundredths_to_deg,
};
pub use decoder::{Counters, Decoder};
pub use frame::{Frame, FrameBytes, MAX_FRAME_LEN, Protocol};

#[cfg(test)]
mod proptests;
