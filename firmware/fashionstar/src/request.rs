//! Request frames (controller → servo): typed requests, their encoder and
//! the parser the simulated servo uses.
//!
//! Payload layouts (little-endian), from the vendor SDK
//! (`fashion_star_uart_servo.c` and `uservo.py`, see the crate root; the
//! moves' layouts are in the `entry` module):
//!
//! | code | request | payload |
//! |---|---|---|
//! | 1 | ping | `id u8` |
//! | 3 | read data | `id u8, address u8` |
//! | 4 | write data | `id u8, address u8, value bytes…` (`FSUS_WriteData`; `uservo.py` `write_data`: `<BB` + content) |
//! | 8 | set angle | [`SetAngle`] |
//! | 9 | damping | `id u8, power u16 (mW)` |
//! | 10 | query angle | `id u8` |
//! | 11 | set angle by interval | [`SetAngleByInterval`] |
//! | 12 | set angle by velocity | [`SetAngleByVelocity`] |
//! | 22 | query monitor | `id u8` |
//! | 25 | sync | `inner code u8, per-servo length u8, count u8`, then `count` payloads of the inner command |
//!
//! Sync inner commands modelled here (`FSUS_SyncCommand`): 8 (length 7),
//! 11 (length 11) and 12 (length 11).

use heapless::Vec;

use crate::entry::{Entry, read_sync, write_sync};
use crate::wire::{PayloadWriter, Reader};
use crate::{
    DecodeError, MAX_PAYLOAD_LEN, MAX_READ_DATA_LEN, Message, REQUEST_HEADER, SetAngle,
    SetAngleByInterval, SetAngleByVelocity, SyncEntries, code,
};

/// A request frame (controller → servo).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Request {
    /// Code 1: is servo `id` there? Answered by [`crate::Response::Ping`].
    Ping {
        /// Servo id.
        id: u8,
    },
    /// Code 3: read one data-table entry. Answered by
    /// [`crate::Response::ReadData`].
    ReadData {
        /// Servo id.
        id: u8,
        /// Data-table address (e.g. 1 voltage, 2 current, 3 power,
        /// 4 temperature, 5 status).
        address: u8,
    },
    /// Code 4: write one data-table entry. Answered by
    /// [`crate::Response::WriteData`].
    WriteData {
        /// Servo id.
        id: u8,
        /// Data-table address (e.g. [`crate::address::SERVO_ID`]).
        address: u8,
        /// The value's bytes (little-endian values, 1 to
        /// [`MAX_READ_DATA_LEN`]).
        data: Vec<u8, MAX_READ_DATA_LEN>,
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
    /// Code 10: query the angle. Answered by [`crate::Response::Angle`].
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
    /// [`crate::Response::Monitor`].
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

/// The motion a request commands one servo to make: what the servo side
/// of a frame acts on (a sync frame commands each servo it addresses with
/// that servo's entry).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MotionCommand {
    /// Move to an angle within a time (code 8, or a sync entry of it).
    SetAngle(SetAngle),
    /// Move within a time with acceleration/deceleration (code 11, or a
    /// sync entry of it).
    SetAngleByInterval(SetAngleByInterval),
    /// Move at a velocity with acceleration/deceleration (code 12, or a
    /// sync entry of it).
    SetAngleByVelocity(SetAngleByVelocity),
    /// Damping mode: stop where it is, resisting with `power_mw` (code 9).
    Damping {
        /// Damping power, mW.
        power_mw: u16,
    },
}

impl Request {
    /// Code 4 at [`crate::address::SERVO_ID`]: servo `id` takes `new_id`
    /// as its bus id (the caller keeps `new_id` at most
    /// [`crate::MAX_SERVO_ID`]).
    pub fn set_servo_id(id: u8, new_id: u8) -> Self {
        let mut data = Vec::new();
        // MAX_READ_DATA_LEN ≥ 1: the push succeeds.
        let _ = data.push(new_id);
        Self::WriteData {
            id,
            address: crate::address::SERVO_ID,
            data,
        }
    }

    /// One sync frame starting a set-angle move on each of `entries`
    /// together; `None` when there are more than [`crate::MAX_SYNC_SERVOS`].
    pub fn sync_set_angle(entries: &[SetAngle]) -> Option<Self> {
        SyncEntries::from_slice(entries)
            .ok()
            .map(Self::SyncSetAngle)
    }

    /// One sync frame starting two set-angle moves together (yaw and
    /// pitch: 22 bytes on the wire).
    pub fn sync_set_angle_pair(first: SetAngle, second: SetAngle) -> Self {
        let mut entries = SyncEntries::new();
        // MAX_SYNC_SERVOS ≥ 2 (asserted in `entry`): both pushes succeed.
        let _ = entries.push(first);
        let _ = entries.push(second);
        Self::SyncSetAngle(entries)
    }

    /// The servo the request addresses; `None` for sync frames, which
    /// address several.
    pub fn id(&self) -> Option<u8> {
        match self {
            Self::Ping { id }
            | Self::ReadData { id, .. }
            | Self::WriteData { id, .. }
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
    /// write data, query monitor). Motion commands are not answered with the servo's
    /// default settings (`FSUS_IS_RESPONSE_ON 0` in the SDK).
    pub fn expects_response(&self) -> bool {
        matches!(
            self,
            Self::Ping { .. }
                | Self::ReadData { .. }
                | Self::WriteData { .. }
                | Self::QueryAngle { .. }
                | Self::QueryMonitor { .. }
        )
    }

    /// The motion this request commands servo `id` to make (from a sync
    /// frame, the first entry addressed to `id`); `None` when it commands
    /// `id` no motion (a query, or a frame for other servos).
    pub fn motion_for(&self, id: u8) -> Option<MotionCommand> {
        match self {
            Self::SetAngle(e) if e.id == id => Some(MotionCommand::SetAngle(*e)),
            Self::SetAngleByInterval(e) if e.id == id => {
                Some(MotionCommand::SetAngleByInterval(*e))
            }
            Self::SetAngleByVelocity(e) if e.id == id => {
                Some(MotionCommand::SetAngleByVelocity(*e))
            }
            Self::Damping { id: to, power_mw } if *to == id => Some(MotionCommand::Damping {
                power_mw: *power_mw,
            }),
            Self::SyncSetAngle(entries) => entry_for(entries, id).map(MotionCommand::SetAngle),
            Self::SyncSetAngleByInterval(entries) => {
                entry_for(entries, id).map(MotionCommand::SetAngleByInterval)
            }
            Self::SyncSetAngleByVelocity(entries) => {
                entry_for(entries, id).map(MotionCommand::SetAngleByVelocity)
            }
            _ => None,
        }
    }
}

impl Message for Request {
    const HEADER: [u8; 2] = REQUEST_HEADER;

    /// Command code of the frame.
    fn code(&self) -> u8 {
        match self {
            Self::Ping { .. } => code::PING,
            Self::ReadData { .. } => code::READ_DATA,
            Self::WriteData { .. } => code::WRITE_DATA,
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

    fn write_payload(&self, w: &mut PayloadWriter) {
        match self {
            Self::Ping { id } | Self::QueryAngle { id } | Self::QueryMonitor { id } => w.u8(*id),
            Self::ReadData { id, address } => {
                w.u8(*id);
                w.u8(*address);
            }
            Self::WriteData { id, address, data } => {
                w.u8(*id);
                w.u8(*address);
                w.bytes(data);
            }
            Self::Damping { id, power_mw } => {
                w.u8(*id);
                w.u16(*power_mw);
            }
            Self::SetAngle(e) => e.write(w),
            Self::SetAngleByInterval(e) => e.write(w),
            Self::SetAngleByVelocity(e) => e.write(w),
            Self::SyncSetAngle(e) => write_sync(w, e),
            Self::SyncSetAngleByInterval(e) => write_sync(w, e),
            Self::SyncSetAngleByVelocity(e) => write_sync(w, e),
        }
    }

    fn payload_len(code: u8) -> Option<(usize, usize)> {
        let exact = |n: u8| Some((usize::from(n), usize::from(n)));
        match code {
            code::PING | code::QUERY_ANGLE | code::QUERY_MONITOR => exact(1),
            code::READ_DATA => exact(2),
            code::WRITE_DATA => Some((3, 2 + MAX_READ_DATA_LEN)),
            code::DAMPING => exact(3),
            code::SET_ANGLE => exact(SetAngle::LEN),
            code::SET_ANGLE_BY_INTERVAL => exact(SetAngleByInterval::LEN),
            code::SET_ANGLE_BY_VELOCITY => exact(SetAngleByVelocity::LEN),
            code::SYNC => Some((3, MAX_PAYLOAD_LEN)),
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
            code::SYNC => parse_sync(&mut r, bad_len)?,
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
            code::WRITE_DATA => {
                let id = r.u8().ok_or(bad_len)?;
                let address = r.u8().ok_or(bad_len)?;
                let data = Vec::from_slice(r.rest()).map_err(|_| bad_len)?;
                r = Reader::new(&[]);
                Self::WriteData { id, address, data }
            }
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
}

/// The first of a sync frame's `entries` addressed to servo `id`.
fn entry_for<const N: usize, T: Entry<N> + Copy>(entries: &[T], id: u8) -> Option<T> {
    entries.iter().copied().find(|e| e.servo_id() == id)
}

/// Parses a sync payload: `bad_len` when its three-byte head is cut short,
/// `BadSync` when the inner command is not modelled or the entries
/// disagree with the head.
fn parse_sync(r: &mut Reader<'_>, bad_len: DecodeError) -> Result<Request, DecodeError> {
    let inner_code = r.u8().ok_or(bad_len)?;
    let len = r.u8().ok_or(bad_len)?;
    let count = r.u8().ok_or(bad_len)?;
    match inner_code {
        code::SET_ANGLE => read_sync(count, len, r).map(Request::SyncSetAngle),
        code::SET_ANGLE_BY_INTERVAL => {
            read_sync(count, len, r).map(Request::SyncSetAngleByInterval)
        }
        code::SET_ANGLE_BY_VELOCITY => {
            read_sync(count, len, r).map(Request::SyncSetAngleByVelocity)
        }
        _ => Err(DecodeError::BadSync { inner_code }),
    }
}

#[cfg(test)]
mod tests;
