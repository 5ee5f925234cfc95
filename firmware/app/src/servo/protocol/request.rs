//! Request frames (controller → servo): typed requests, their encoder and
//! the parser the simulated servo uses.
//!
//! Payload layouts (little-endian), from the vendor SDK
//! (`fashion_star_uart_servo.c` and `uservo.py`, see the module root):
//!
//! | code | request | payload |
//! |---|---|---|
//! | 1 | ping | `id u8` |
//! | 3 | read data | `id u8, address u8` |
//! | 8 | set angle | `id u8, angle i16 (0.1°), interval u16 (ms), power u16 (mW)` |
//! | 9 | damping | `id u8, power u16 (mW)` |
//! | 10 | query angle | `id u8` |
//! | 11 | set angle by interval | `id, angle i16, interval u16, t_acc u16, t_dec u16, power u16` |
//! | 12 | set angle by velocity | `id, angle i16, velocity u16 (0.1°/s), t_acc u16, t_dec u16, power u16` |
//! | 22 | query monitor | `id u8` |
//! | 25 | sync | `inner code u8, per-servo length u8, count u8`, then `count` payloads of the inner command |
//!
//! Sync inner commands modelled here (`FSUS_SyncCommand`): 8 (length 7),
//! 11 (length 11) and 12 (length 11).

use heapless::Vec;

use super::decoder::Message;
use super::wire::{Reader, Writer, write_frame};
use super::{
    ANGLE_LIMIT_TENTHS_DEG, DecodeError, EncodeError, FRAME_OVERHEAD, MAX_FRAME_LEN,
    MAX_SYNC_SERVOS, MAX_VELOCITY_TENTHS_DEG_S, MIN_ACC_DEC_MS, MIN_VELOCITY_TENTHS_DEG_S,
    REQUEST_HEADER, code,
};

const _: () = assert!(MAX_SYNC_SERVOS >= 2 && MAX_SYNC_SERVOS <= u8::MAX as usize);

/// Per-servo entries of one sync frame (at most [`MAX_SYNC_SERVOS`]).
pub type SyncEntries<T> = Vec<T, MAX_SYNC_SERVOS>;

/// Move to an angle within a time (code 8; also the sync entry with
/// inner code 8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SetAngle {
    /// Servo id.
    pub id: u8,
    /// Target angle, 0.1° (the servo's range is ±1800).
    pub angle_tenths_deg: i16,
    /// Time to get there, ms.
    pub interval_ms: u16,
    /// Power limit, mW (0: the servo's own limit).
    pub power_mw: u16,
}

/// Move to an angle within a time with acceleration and deceleration
/// phases (code 11; also the sync entry with inner code 11).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SetAngleByInterval {
    /// Servo id.
    pub id: u8,
    /// Target angle, 0.1°.
    pub angle_tenths_deg: i16,
    /// Time to get there, ms.
    pub interval_ms: u16,
    /// Acceleration time, ms (the SDK sends at least 20).
    pub t_acc_ms: u16,
    /// Deceleration time, ms (the SDK sends at least 20).
    pub t_dec_ms: u16,
    /// Power limit, mW (0: the servo's own limit).
    pub power_mw: u16,
}

/// Move to an angle at a velocity with acceleration and deceleration
/// phases (code 12; also the sync entry with inner code 12).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SetAngleByVelocity {
    /// Servo id.
    pub id: u8,
    /// Target angle, 0.1°.
    pub angle_tenths_deg: i16,
    /// Cruise velocity, 0.1°/s (the SDK sends 10..=7500).
    pub velocity_tenths_deg_s: u16,
    /// Acceleration time, ms (the SDK sends at least 20).
    pub t_acc_ms: u16,
    /// Deceleration time, ms (the SDK sends at least 20).
    pub t_dec_ms: u16,
    /// Power limit, mW (0: the servo's own limit).
    pub power_mw: u16,
}

fn clamp_angle(angle_tenths_deg: i16) -> i16 {
    angle_tenths_deg.clamp(-ANGLE_LIMIT_TENTHS_DEG, ANGLE_LIMIT_TENTHS_DEG)
}

impl SetAngle {
    /// The request as the vendor SDK would send it: angle clamped to
    /// ±180.0°.
    pub fn with_sdk_limits(self) -> Self {
        Self {
            angle_tenths_deg: clamp_angle(self.angle_tenths_deg),
            ..self
        }
    }
}

impl SetAngleByInterval {
    /// The request as the vendor SDK would send it: angle clamped to
    /// ±180.0°, acceleration and deceleration times at least 20 ms.
    pub fn with_sdk_limits(self) -> Self {
        Self {
            angle_tenths_deg: clamp_angle(self.angle_tenths_deg),
            t_acc_ms: self.t_acc_ms.max(MIN_ACC_DEC_MS),
            t_dec_ms: self.t_dec_ms.max(MIN_ACC_DEC_MS),
            ..self
        }
    }
}

impl SetAngleByVelocity {
    /// The request as the vendor SDK would send it: angle clamped to
    /// ±180.0°, velocity to 1..=750 °/s, acceleration and deceleration
    /// times at least 20 ms.
    pub fn with_sdk_limits(self) -> Self {
        Self {
            angle_tenths_deg: clamp_angle(self.angle_tenths_deg),
            velocity_tenths_deg_s: self
                .velocity_tenths_deg_s
                .clamp(MIN_VELOCITY_TENTHS_DEG_S, MAX_VELOCITY_TENTHS_DEG_S),
            t_acc_ms: self.t_acc_ms.max(MIN_ACC_DEC_MS),
            t_dec_ms: self.t_dec_ms.max(MIN_ACC_DEC_MS),
            ..self
        }
    }
}

/// A per-servo command that can travel alone or inside a sync frame.
trait Entry: Sized {
    /// Code of the command (the inner code in a sync frame).
    const CODE: u8;
    /// Payload length, bytes (the per-servo length in a sync frame).
    const LEN: u8;
    fn write(&self, w: &mut Writer);
    fn read(r: &mut Reader<'_>) -> Option<Self>;
}

impl Entry for SetAngle {
    const CODE: u8 = code::SET_ANGLE;
    const LEN: u8 = 7;
    fn write(&self, w: &mut Writer) {
        w.u8(self.id);
        w.i16(self.angle_tenths_deg);
        w.u16(self.interval_ms);
        w.u16(self.power_mw);
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        Some(Self {
            id: r.u8()?,
            angle_tenths_deg: r.i16()?,
            interval_ms: r.u16()?,
            power_mw: r.u16()?,
        })
    }
}

impl Entry for SetAngleByInterval {
    const CODE: u8 = code::SET_ANGLE_BY_INTERVAL;
    const LEN: u8 = 11;
    fn write(&self, w: &mut Writer) {
        w.u8(self.id);
        w.i16(self.angle_tenths_deg);
        w.u16(self.interval_ms);
        w.u16(self.t_acc_ms);
        w.u16(self.t_dec_ms);
        w.u16(self.power_mw);
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        Some(Self {
            id: r.u8()?,
            angle_tenths_deg: r.i16()?,
            interval_ms: r.u16()?,
            t_acc_ms: r.u16()?,
            t_dec_ms: r.u16()?,
            power_mw: r.u16()?,
        })
    }
}

impl Entry for SetAngleByVelocity {
    const CODE: u8 = code::SET_ANGLE_BY_VELOCITY;
    const LEN: u8 = 11;
    fn write(&self, w: &mut Writer) {
        w.u8(self.id);
        w.i16(self.angle_tenths_deg);
        w.u16(self.velocity_tenths_deg_s);
        w.u16(self.t_acc_ms);
        w.u16(self.t_dec_ms);
        w.u16(self.power_mw);
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        Some(Self {
            id: r.u8()?,
            angle_tenths_deg: r.i16()?,
            velocity_tenths_deg_s: r.u16()?,
            t_acc_ms: r.u16()?,
            t_dec_ms: r.u16()?,
            power_mw: r.u16()?,
        })
    }
}

/// A request frame (controller → servo).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Request {
    /// Code 1: is servo `id` there? Answered by [`super::Response::Ping`].
    Ping {
        /// Servo id.
        id: u8,
    },
    /// Code 3: read one data-table entry. Answered by
    /// [`super::Response::ReadData`].
    ReadData {
        /// Servo id.
        id: u8,
        /// Data-table address (e.g. 1 voltage, 2 current, 3 power,
        /// 4 temperature, 5 status).
        address: u8,
    },
    /// Code 8: move to an angle within a time. No response.
    SetAngle(SetAngle),
    /// Code 9: damping mode (passive, resisting with `power_mw`). No
    /// response.
    Damping {
        /// Servo id.
        id: u8,
        /// Damping power, mW.
        power_mw: u16,
    },
    /// Code 10: query the angle. Answered by [`super::Response::Angle`].
    QueryAngle {
        /// Servo id.
        id: u8,
    },
    /// Code 11: move within a time with acceleration/deceleration. No
    /// response.
    SetAngleByInterval(SetAngleByInterval),
    /// Code 12: move at a velocity with acceleration/deceleration. No
    /// response.
    SetAngleByVelocity(SetAngleByVelocity),
    /// Code 22: query monitor data. Answered by
    /// [`super::Response::Monitor`].
    QueryMonitor {
        /// Servo id.
        id: u8,
    },
    /// Code 25 with inner code 8: start several set-angle moves together.
    /// No response.
    SyncSetAngle(SyncEntries<SetAngle>),
    /// Code 25 with inner code 11. No response.
    SyncSetAngleByInterval(SyncEntries<SetAngleByInterval>),
    /// Code 25 with inner code 12. No response.
    SyncSetAngleByVelocity(SyncEntries<SetAngleByVelocity>),
}

fn write_sync<T: Entry>(w: &mut Writer, entries: &[T]) {
    w.u8(T::CODE);
    w.u8(T::LEN);
    // At most MAX_SYNC_SERVOS (≤ 255, asserted above) entries.
    w.u8(entries.len() as u8);
    for entry in entries {
        entry.write(w);
    }
}

fn read_sync<T: Entry>(
    count: u8,
    len: u8,
    r: &mut Reader<'_>,
    inner_code: u8,
) -> Result<SyncEntries<T>, DecodeError> {
    let bad = DecodeError::BadSync { inner_code };
    if len != T::LEN || r.rest().len() != usize::from(count) * usize::from(len) {
        return Err(bad);
    }
    let mut entries = SyncEntries::new();
    for _ in 0..count {
        let entry = T::read(r).ok_or(bad)?;
        entries.push(entry).map_err(|_| bad)?;
    }
    Ok(entries)
}

impl Request {
    /// One sync frame starting a set-angle move on each of `entries`
    /// together; `None` when there are more than [`MAX_SYNC_SERVOS`].
    pub fn sync_set_angle(entries: &[SetAngle]) -> Option<Self> {
        SyncEntries::from_slice(entries)
            .ok()
            .map(Self::SyncSetAngle)
    }

    /// One sync frame starting two set-angle moves together (yaw and
    /// pitch: 22 bytes on the wire).
    pub fn sync_set_angle_pair(first: SetAngle, second: SetAngle) -> Self {
        let mut entries = SyncEntries::new();
        // MAX_SYNC_SERVOS ≥ 2 (asserted above): both pushes succeed.
        let _ = entries.push(first);
        let _ = entries.push(second);
        Self::SyncSetAngle(entries)
    }

    /// Command code of the frame.
    pub fn code(&self) -> u8 {
        match self {
            Self::Ping { .. } => code::PING,
            Self::ReadData { .. } => code::READ_DATA,
            Self::SetAngle(_) => code::SET_ANGLE,
            Self::Damping { .. } => code::DAMPING,
            Self::QueryAngle { .. } => code::QUERY_ANGLE,
            Self::SetAngleByInterval(_) => code::SET_ANGLE_BY_INTERVAL,
            Self::SetAngleByVelocity(_) => code::SET_ANGLE_BY_VELOCITY,
            Self::QueryMonitor { .. } => code::QUERY_MONITOR,
            Self::SyncSetAngle(_)
            | Self::SyncSetAngleByInterval(_)
            | Self::SyncSetAngleByVelocity(_) => code::SYNC,
        }
    }

    /// The servo the request addresses; `None` for sync frames, which
    /// address several.
    pub fn id(&self) -> Option<u8> {
        match self {
            Self::Ping { id }
            | Self::ReadData { id, .. }
            | Self::Damping { id, .. }
            | Self::QueryAngle { id }
            | Self::QueryMonitor { id }
            | Self::SetAngle(SetAngle { id, .. })
            | Self::SetAngleByInterval(SetAngleByInterval { id, .. })
            | Self::SetAngleByVelocity(SetAngleByVelocity { id, .. }) => Some(*id),
            Self::SyncSetAngle(_)
            | Self::SyncSetAngleByInterval(_)
            | Self::SyncSetAngleByVelocity(_) => None,
        }
    }

    /// Whether the addressed servo answers (ping, read data, query angle,
    /// query monitor). Motion commands are not answered with the servo's
    /// default settings (`FSUS_IS_RESPONSE_ON 0` in the SDK).
    pub fn expects_response(&self) -> bool {
        matches!(
            self,
            Self::Ping { .. }
                | Self::ReadData { .. }
                | Self::QueryAngle { .. }
                | Self::QueryMonitor { .. }
        )
    }

    fn payload(&self) -> Result<super::wire::Payload, EncodeError> {
        let mut w = Writer::new();
        match self {
            Self::Ping { id } | Self::QueryAngle { id } | Self::QueryMonitor { id } => w.u8(*id),
            Self::ReadData { id, address } => {
                w.u8(*id);
                w.u8(*address);
            }
            Self::Damping { id, power_mw } => {
                w.u8(*id);
                w.u16(*power_mw);
            }
            Self::SetAngle(e) => e.write(&mut w),
            Self::SetAngleByInterval(e) => e.write(&mut w),
            Self::SetAngleByVelocity(e) => e.write(&mut w),
            Self::SyncSetAngle(e) => write_sync(&mut w, e),
            Self::SyncSetAngleByInterval(e) => write_sync(&mut w, e),
            Self::SyncSetAngleByVelocity(e) => write_sync(&mut w, e),
        }
        w.finish()
    }

    /// Frame length on the wire, bytes.
    pub fn encoded_len(&self) -> usize {
        self.payload()
            .map_or(MAX_FRAME_LEN, |p| p.len() + FRAME_OVERHEAD)
    }

    /// Writes the frame into `out`; returns its length in bytes (at most
    /// [`MAX_FRAME_LEN`]).
    pub fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        write_frame(REQUEST_HEADER, self.code(), &self.payload()?, out)
    }

    /// The frame as a vector.
    pub fn to_frame(&self) -> Result<Vec<u8, MAX_FRAME_LEN>, EncodeError> {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let len = self.encode(&mut buf)?;
        Vec::from_slice(buf.get(..len).unwrap_or(&[]))
            .map_err(|_| EncodeError::BufferTooSmall { needed: len })
    }
}

impl Message for Request {
    const HEADER: [u8; 2] = REQUEST_HEADER;

    fn payload_len(code: u8) -> Option<(usize, usize)> {
        let exact = |n: u8| Some((usize::from(n), usize::from(n)));
        match code {
            code::PING | code::QUERY_ANGLE | code::QUERY_MONITOR => exact(1),
            code::READ_DATA => exact(2),
            code::DAMPING => exact(3),
            code::SET_ANGLE => exact(SetAngle::LEN),
            code::SET_ANGLE_BY_INTERVAL => exact(SetAngleByInterval::LEN),
            code::SET_ANGLE_BY_VELOCITY => exact(SetAngleByVelocity::LEN),
            code::SYNC => Some((3, super::MAX_PAYLOAD_LEN)),
            _ => None,
        }
    }

    fn parse(code: u8, payload: &[u8]) -> Result<Self, DecodeError> {
        let bad_len = DecodeError::BadLength {
            code,
            len: u8::try_from(payload.len()).unwrap_or(u8::MAX),
        };
        let mut r = Reader::new(payload);
        let request = match code {
            code::SYNC => {
                let inner_code = r.u8().ok_or(bad_len)?;
                let len = r.u8().ok_or(bad_len)?;
                let count = r.u8().ok_or(bad_len)?;
                let r = &mut r;
                match inner_code {
                    code::SET_ANGLE => Self::SyncSetAngle(read_sync(count, len, r, inner_code)?),
                    code::SET_ANGLE_BY_INTERVAL => {
                        Self::SyncSetAngleByInterval(read_sync(count, len, r, inner_code)?)
                    }
                    code::SET_ANGLE_BY_VELOCITY => {
                        Self::SyncSetAngleByVelocity(read_sync(count, len, r, inner_code)?)
                    }
                    _ => return Err(DecodeError::BadSync { inner_code }),
                }
            }
            code::PING => Self::Ping {
                id: r.u8().ok_or(bad_len)?,
            },
            code::QUERY_ANGLE => Self::QueryAngle {
                id: r.u8().ok_or(bad_len)?,
            },
            code::QUERY_MONITOR => Self::QueryMonitor {
                id: r.u8().ok_or(bad_len)?,
            },
            code::READ_DATA => Self::ReadData {
                id: r.u8().ok_or(bad_len)?,
                address: r.u8().ok_or(bad_len)?,
            },
            code::DAMPING => Self::Damping {
                id: r.u8().ok_or(bad_len)?,
                power_mw: r.u16().ok_or(bad_len)?,
            },
            code::SET_ANGLE => Self::SetAngle(SetAngle::read(&mut r).ok_or(bad_len)?),
            code::SET_ANGLE_BY_INTERVAL => {
                Self::SetAngleByInterval(SetAngleByInterval::read(&mut r).ok_or(bad_len)?)
            }
            code::SET_ANGLE_BY_VELOCITY => {
                Self::SetAngleByVelocity(SetAngleByVelocity::read(&mut r).ok_or(bad_len)?)
            }
            _ => return Err(DecodeError::UnknownCode { code }),
        };
        r.end().ok_or(bad_len)?;
        Ok(request)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        Request::encode(self, out)
    }
}

#[cfg(test)]
mod tests {
    //! Known-answer frames: each expected frame is spelled out from the
    //! layout, with the checksum summed by hand in the comment.
    extern crate std;
    use super::*;

    fn frame(r: &Request) -> std::vec::Vec<u8> {
        let mut out = [0u8; MAX_FRAME_LEN];
        let n = r.encode(&mut out).unwrap();
        assert_eq!(n, r.encoded_len());
        out[..n].to_vec()
    }

    #[test]
    fn ping() {
        // 12+4C+01+01+00 = 0x60
        assert_eq!(
            frame(&Request::Ping { id: 0 }),
            [0x12, 0x4C, 0x01, 0x01, 0x00, 0x60]
        );
        // 0x60 + 1 = 0x61
        assert_eq!(
            frame(&Request::Ping { id: 1 }),
            [0x12, 0x4C, 0x01, 0x01, 0x01, 0x61]
        );
    }

    #[test]
    fn query_angle_monitor_read_data() {
        // 12+4C+0A+01+01 = 0x6A
        assert_eq!(
            frame(&Request::QueryAngle { id: 1 }),
            [0x12, 0x4C, 0x0A, 0x01, 0x01, 0x6A]
        );
        // 12+4C+16+01+00 = 0x75
        assert_eq!(
            frame(&Request::QueryMonitor { id: 0 }),
            [0x12, 0x4C, 0x16, 0x01, 0x00, 0x75]
        );
        // 12+4C+03+02+01+05 = 0x69
        assert_eq!(
            frame(&Request::ReadData { id: 1, address: 5 }),
            [0x12, 0x4C, 0x03, 0x02, 0x01, 0x05, 0x69]
        );
    }

    #[test]
    fn set_angle() {
        // id 0, 90.0° = 900 = 0x0384, 500 ms = 0x01F4, power 0:
        // 5E (12+4C) +08+07+00 = 6D; +84+03 = F4; +F4+01 = 1E9; +00+00 → 0xE9
        let r = Request::SetAngle(SetAngle {
            id: 0,
            angle_tenths_deg: 900,
            interval_ms: 500,
            power_mw: 0,
        });
        assert_eq!(
            frame(&r),
            [
                0x12, 0x4C, 0x08, 0x07, 0x00, 0x84, 0x03, 0xF4, 0x01, 0x00, 0x00, 0xE9
            ]
        );
        // id 1, -45.5° = -455 = 0xFE39, 1000 ms = 0x03E8, 2000 mW = 0x07D0:
        // 5E (12+4C) +08+07+01 = 6E; +39+FE = 1A5; +E8+03 = 290; +D0+07 = 367 → 0x67
        let r = Request::SetAngle(SetAngle {
            id: 1,
            angle_tenths_deg: -455,
            interval_ms: 1000,
            power_mw: 2000,
        });
        assert_eq!(
            frame(&r),
            [
                0x12, 0x4C, 0x08, 0x07, 0x01, 0x39, 0xFE, 0xE8, 0x03, 0xD0, 0x07, 0x67
            ]
        );
    }

    #[test]
    fn damping() {
        // id 0, 500 mW = 0x01F4: 5E (12+4C) +09+03+00 = 6A; +F4+01 = 15F → 0x5F
        assert_eq!(
            frame(&Request::Damping {
                id: 0,
                power_mw: 500
            }),
            [0x12, 0x4C, 0x09, 0x03, 0x00, 0xF4, 0x01, 0x5F]
        );
    }

    #[test]
    fn set_angle_by_interval_and_velocity() {
        // id 0, 90.0° (84 03), 1000 ms (E8 03), t_acc 100 (64 00),
        // t_dec 150 (96 00), power 0:
        // 5E (12+4C) +0B+0B+00 = 74; +84+03 = FB; +E8+03 = 1E6; +64+00 = 24A;
        // +96+00 = 2E0; +00+00 → 0xE0
        let r = Request::SetAngleByInterval(SetAngleByInterval {
            id: 0,
            angle_tenths_deg: 900,
            interval_ms: 1000,
            t_acc_ms: 100,
            t_dec_ms: 150,
            power_mw: 0,
        });
        assert_eq!(
            frame(&r),
            [
                0x12, 0x4C, 0x0B, 0x0B, 0x00, 0x84, 0x03, 0xE8, 0x03, 0x64, 0x00, 0x96, 0x00, 0x00,
                0x00, 0xE0
            ]
        );
        // id 1, -90.0° = -900 = 0xFC7C, 200.0 °/s = 2000 = 0x07D0,
        // t_acc 20 (14 00), t_dec 20 (14 00), power 0:
        // 5E (12+4C) +0C+0B+01 = 76; +7C+FC = 1EE; +D0+07 = 2C5; +14+00 = 2D9;
        // +14+00 = 2ED; +00+00 → 0xED
        let r = Request::SetAngleByVelocity(SetAngleByVelocity {
            id: 1,
            angle_tenths_deg: -900,
            velocity_tenths_deg_s: 2000,
            t_acc_ms: 20,
            t_dec_ms: 20,
            power_mw: 0,
        });
        assert_eq!(
            frame(&r),
            [
                0x12, 0x4C, 0x0C, 0x0B, 0x01, 0x7C, 0xFC, 0xD0, 0x07, 0x14, 0x00, 0x14, 0x00, 0x00,
                0x00, 0xED
            ]
        );
    }

    #[test]
    fn sync_set_angle_pair_is_22_bytes() {
        // inner 08, len 07, count 02;
        // id 0, 10.0° (64 00), 300 ms (2C 01), power 0;
        // id 1, -20.0° = -200 = 0xFF38 (38 FF), 300 ms, power 0.
        // 12+4C+19+11 = 0x88; +08+07+02 = 0x99;
        // +00+64+00+2C+01+00+00 = 0x12A; +01+38+FF+2C+01+00+00 = 0x28F → 0x8F
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
        let f = frame(&r);
        assert_eq!(f.len(), 22);
        assert_eq!(
            f,
            [
                0x12, 0x4C, 0x19, 0x11, 0x08, 0x07, 0x02, 0x00, 0x64, 0x00, 0x2C, 0x01, 0x00, 0x00,
                0x01, 0x38, 0xFF, 0x2C, 0x01, 0x00, 0x00, 0x8F
            ]
        );
    }

    #[test]
    fn sync_by_interval_and_velocity_layouts() {
        let a = SetAngleByInterval {
            id: 2,
            angle_tenths_deg: 1,
            interval_ms: 2,
            t_acc_ms: 3,
            t_dec_ms: 4,
            power_mw: 5,
        };
        let mut e = SyncEntries::new();
        e.push(a).unwrap();
        let f = frame(&Request::SyncSetAngleByInterval(e));
        // 5 + 3 + 11 bytes; header, inner 0B, len 0B, count 01, then the
        // code-11 payload.
        assert_eq!(f.len(), 19);
        assert_eq!(&f[..7], &[0x12, 0x4C, 0x19, 0x0E, 0x0B, 0x0B, 0x01]);
        assert_eq!(&f[7..18], &[2, 1, 0, 2, 0, 3, 0, 4, 0, 5, 0]);
        let v = SetAngleByVelocity {
            id: 2,
            angle_tenths_deg: 1,
            velocity_tenths_deg_s: 2,
            t_acc_ms: 3,
            t_dec_ms: 4,
            power_mw: 5,
        };
        let f = frame(&Request::SyncSetAngleByVelocity(
            SyncEntries::from_slice(&[v, v]).unwrap(),
        ));
        assert_eq!(f.len(), 30);
        assert_eq!(&f[..7], &[0x12, 0x4C, 0x19, 0x19, 0x0C, 0x0B, 0x02]);
        assert_eq!(&f[18..29], &[2, 1, 0, 2, 0, 3, 0, 4, 0, 5, 0]);
    }

    #[test]
    fn sync_limits() {
        let e = SetAngle {
            id: 0,
            angle_tenths_deg: 0,
            interval_ms: 0,
            power_mw: 0,
        };
        assert!(Request::sync_set_angle(&[e; MAX_SYNC_SERVOS]).is_some());
        assert!(Request::sync_set_angle(&[e; MAX_SYNC_SERVOS + 1]).is_none());
        let full = SetAngleByVelocity {
            id: 0,
            angle_tenths_deg: 0,
            velocity_tenths_deg_s: 0,
            t_acc_ms: 0,
            t_dec_ms: 0,
            power_mw: 0,
        };
        let r = Request::SyncSetAngleByVelocity(
            SyncEntries::from_slice(&[full; MAX_SYNC_SERVOS]).unwrap(),
        );
        assert_eq!(r.encoded_len(), MAX_FRAME_LEN);
    }

    #[test]
    fn short_buffer_is_an_error() {
        let mut out = [0u8; 5];
        assert_eq!(
            Request::Ping { id: 0 }.encode(&mut out),
            Err(EncodeError::BufferTooSmall { needed: 6 })
        );
    }

    #[test]
    fn sdk_limits() {
        let v = SetAngleByVelocity {
            id: 0,
            angle_tenths_deg: 2000,
            velocity_tenths_deg_s: 9000,
            t_acc_ms: 0,
            t_dec_ms: 5,
            power_mw: 0,
        }
        .with_sdk_limits();
        assert_eq!(
            (
                v.angle_tenths_deg,
                v.velocity_tenths_deg_s,
                v.t_acc_ms,
                v.t_dec_ms
            ),
            (1800, 7500, 20, 20)
        );
        let a = SetAngle {
            id: 0,
            angle_tenths_deg: -3000,
            interval_ms: 0,
            power_mw: 0,
        };
        assert_eq!(a.with_sdk_limits().angle_tenths_deg, -1800);
        let i = SetAngleByInterval {
            id: 0,
            angle_tenths_deg: 5,
            interval_ms: 10,
            t_acc_ms: 30,
            t_dec_ms: 1,
            power_mw: 0,
        }
        .with_sdk_limits();
        assert_eq!((i.angle_tenths_deg, i.t_acc_ms, i.t_dec_ms), (5, 30, 20));
    }

    #[test]
    fn metadata() {
        assert_eq!(Request::Ping { id: 3 }.id(), Some(3));
        assert!(Request::Ping { id: 3 }.expects_response());
        let e = SetAngle {
            id: 0,
            angle_tenths_deg: 0,
            interval_ms: 0,
            power_mw: 0,
        };
        assert!(!Request::SetAngle(e).expects_response());
        assert_eq!(Request::sync_set_angle_pair(e, e).id(), None);
        assert_eq!(Request::sync_set_angle_pair(e, e).code(), code::SYNC);
    }

    #[test]
    fn parse_rejects_inconsistent_sync() {
        // Per-servo length 11 with inner code 8.
        assert_eq!(
            Request::parse(code::SYNC, &[8, 11, 0]),
            Err(DecodeError::BadSync { inner_code: 8 })
        );
        // Count 2 but one entry.
        assert_eq!(
            Request::parse(code::SYNC, &[8, 7, 2, 0, 0, 0, 0, 0, 0, 0]),
            Err(DecodeError::BadSync { inner_code: 8 })
        );
        // Inner code not modelled (22: sync monitor).
        assert_eq!(
            Request::parse(code::SYNC, &[22, 1, 1, 0]),
            Err(DecodeError::BadSync { inner_code: 22 })
        );
        // Too many servos for the codec.
        let mut p = std::vec![8u8, 7, 5];
        p.extend([0u8; 35]);
        assert_eq!(
            Request::parse(code::SYNC, &p),
            Err(DecodeError::BadSync { inner_code: 8 })
        );
        // Empty sync is a valid (if useless) frame.
        assert_eq!(
            Request::parse(code::SYNC, &[8, 7, 0]),
            Ok(Request::SyncSetAngle(SyncEntries::new()))
        );
    }
}
