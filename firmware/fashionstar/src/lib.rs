#![no_std]
//! FashionStar serial-bus servo protocol: typed requests and responses,
//! byte-exact frame encoders and streaming, resynchronising decoders for
//! both directions (the firmware decodes responses, the simulated servo
//! decodes requests). `no_std`, no allocation, fixed buffers.
//!
//! The code follows the frame (SPEC §7): [`Message`] is one direction's
//! frame type (its header, a code, a payload) and derives the framing,
//! length and checksum for every message once ([`Message::encode`],
//! [`Message::to_frame`], [`Message::encoded_len`]); [`Request`] and
//! [`Response`] only say how their payloads are laid out. The per-servo
//! moves ([`SetAngle`], [`SetAngleByInterval`], [`SetAngleByVelocity`])
//! have one layout (`id, angle, u16 fields`) whether they travel alone or
//! as entries of a sync frame. [`StreamDecoder`] turns bytes back into
//! messages of either direction.
//!
//! # Frame layout
//!
//! ```text
//! request:  12 4C | code | len | payload (len bytes) | checksum
//! response: 05 1C | code | len | payload (len bytes) | checksum
//! ```
//!
//! `checksum` is the sum of every preceding byte of the frame, header
//! included, mod 256; multi-byte fields are little-endian.
//!
//! Sources of the layout facts (SPEC §7, checked against the vendor SDK
//! `servodevelop/servo-uart-rs485-sdk`, commit 772c181):
//! * headers, codes, checksum, length byte: `STM32F407/STM32F407_SDK/HARDWARE/
//!   fashion_star_uart_servo/fashion_star_uart_servo.{h,c}`
//!   (`FSUS_PACK_REQUEST_HEADER 0x4c12` written as a native little-endian
//!   `u16`, i.e. `12 4C`; `FSUS_Package2RingBuffer`; `RingBuffer_GetChecksum`
//!   in `ring_buffer.c` sums every byte already written, header included);
//! * payload layouts: the same C file (`FSUS_SetServoAngle`,
//!   `FSUS_SetServoAngleByInterval`, `FSUS_SetServoAngleByVelocity`,
//!   `FSUS_DampingMode`, `FSUS_QueryServoAngle`, `FSUS_ReadData`,
//!   `FSUS_WriteData`,
//!   `FSUS_ServoMonitor`, `FSUS_SyncCommand`) and the MicroPython SDK
//!   `micro-python/src/uservo.py` (`struct` formats `<BhHH`, `<BhHHHH`,
//!   `<BH`, `<Bh`, `<BB`, `<BHHHHBih`, sync header `<BBB`; `write_data`
//!   packs `<BB` then the value bytes, `response_write_data` unpacks
//!   `<BBB`).
//! * A length byte of `0xFF` announces a 16-bit length (the SDK uses it only
//!   for payloads over 255 bytes); such frames exceed [`MAX_PAYLOAD_LEN`]
//!   and are rejected as [`DecodeError::BadLength`].

mod decoder;
mod entry;
mod message;
mod request;
mod response;
mod wire;

#[cfg(test)]
mod proptests;
#[cfg(any(test, feature = "testing"))]
pub mod testing;

pub use decoder::{Decoded, RequestDecoder, ResponseDecoder, StreamDecoder};
pub use entry::{SetAngle, SetAngleByInterval, SetAngleByVelocity, SyncEntries};
pub use message::{Frame, Message};
pub use request::{MotionCommand, Request};
pub use response::{Monitor, ReadData, Response, WriteResult};
pub use wire::{PayloadWriter, checksum};

/// First two bytes of every request frame (controller → servo).
pub const REQUEST_HEADER: [u8; 2] = [0x12, 0x4C];
/// First two bytes of every response frame (servo → controller).
pub const RESPONSE_HEADER: [u8; 2] = [0x05, 0x1C];

/// Command codes (the byte after the header), as in the vendor SDK.
pub mod code {
    /// Ping: request `id`, response `id`.
    pub const PING: u8 = 1;
    /// Read one entry of the servo's data table: `id, address` → `id,
    /// address, bytes`.
    pub const READ_DATA: u8 = 3;
    /// Write one entry of the servo's data table: `id, address, bytes` →
    /// `id, address, result` (1 = written).
    pub const WRITE_DATA: u8 = 4;
    /// Set angle (single turn): `id, angle, interval, power`; no response.
    pub const SET_ANGLE: u8 = 8;
    /// Damping mode: `id, power`; no response.
    pub const DAMPING: u8 = 9;
    /// Query angle: `id` → `id, angle`.
    pub const QUERY_ANGLE: u8 = 10;
    /// Set angle by interval with acceleration/deceleration times.
    pub const SET_ANGLE_BY_INTERVAL: u8 = 11;
    /// Set angle by velocity with acceleration/deceleration times.
    pub const SET_ANGLE_BY_VELOCITY: u8 = 12;
    /// Query monitor data: `id` → voltage, current, power, temperature,
    /// status, angle, turns.
    pub const QUERY_MONITOR: u8 = 22;
    /// Sync command: one frame carrying one inner command for many servos.
    pub const SYNC: u8 = 25;
}

/// Header, code, length and checksum bytes around the payload.
pub const FRAME_OVERHEAD: usize = 5;
/// Most servos one sync frame may address (the codec's limit, not the
/// vendor's: two are needed, yaw and pitch).
pub const MAX_SYNC_SERVOS: usize = 4;
/// Most data bytes a read-data response (or a write-data request) may
/// carry.
pub const MAX_READ_DATA_LEN: usize = 32;

/// Data-table addresses (`FSUS_PARAM_*` in the SDK's
/// `fashion_star_uart_servo.h`).
pub mod address {
    /// The servo's bus id (`FSUS_PARAM_SERVO_ID`, 1 byte, 0–254; 255 is
    /// the broadcast address and never assignable).
    pub const SERVO_ID: u8 = 34;
}

/// Highest id a servo can be given (255 is the broadcast address).
pub const MAX_SERVO_ID: u8 = 254;
/// Longest payload either direction: a sync by interval/velocity frame for
/// [`MAX_SYNC_SERVOS`] servos (3 + 4 × 11 = 47 bytes).
pub const MAX_PAYLOAD_LEN: usize = 3 + MAX_SYNC_SERVOS * 11;
/// Longest frame either direction, bytes (52).
pub const MAX_FRAME_LEN: usize = MAX_PAYLOAD_LEN + FRAME_OVERHEAD;

/// Servo angle range the SDK clamps commanded angles to, 0.1° (±180.0°).
pub const ANGLE_LIMIT_TENTHS_DEG: i16 = 1800;
/// Highest velocity the SDK sends, 0.1°/s (750 °/s).
pub const MAX_VELOCITY_TENTHS_DEG_S: u16 = 7500;
/// Lowest velocity the SDK sends, 0.1°/s (1 °/s).
pub const MIN_VELOCITY_TENTHS_DEG_S: u16 = 10;
/// Shortest acceleration/deceleration time the SDK sends, ms.
pub const MIN_ACC_DEC_MS: u16 = 20;

/// A frame could not be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EncodeError {
    /// The output buffer is shorter than the frame.
    BufferTooSmall {
        /// Frame length, bytes.
        needed: usize,
    },
}

/// A byte sequence that started with a frame header was not a valid frame.
/// The decoder reports it and resynchronises by itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DecodeError {
    /// The declared payload length does not fit the code (or exceeds
    /// [`MAX_PAYLOAD_LEN`]); scanning resumes after the header.
    BadLength {
        /// Command code.
        code: u8,
        /// Declared payload length, bytes.
        len: u8,
    },
    /// The checksum byte differs from the sum of the preceding bytes;
    /// scanning resumes after the header, so a real frame hidden inside
    /// the false one is still found.
    BadChecksum {
        /// Command code.
        code: u8,
        /// Checksum computed from the received bytes.
        computed: u8,
        /// Checksum byte received.
        received: u8,
    },
    /// An intact frame (valid checksum) with a code this codec does not
    /// model; it is skipped whole.
    UnknownCode {
        /// Command code.
        code: u8,
    },
    /// An intact sync frame whose inner command is not modelled or whose
    /// count and per-servo length disagree with its length; skipped whole.
    BadSync {
        /// Inner command code.
        inner_code: u8,
    },
}
