//! Response frames (servo → controller): typed responses, the parser the
//! firmware uses and the encoder the simulated servo uses.
//!
//! Payload layouts (little-endian), from the vendor SDK (`FSUS_Ping`,
//! `FSUS_QueryServoAngle`, `FSUS_ReadData`, `FSUS_ServoMonitor` in
//! `fashion_star_uart_servo.c`; `response_*` and `'<BHHHHBih'` in
//! `uservo.py`):
//!
//! | code | response | payload |
//! |---|---|---|
//! | 1 | ping | `id u8` |
//! | 3 | read data | `id u8, address u8, data…` |
//! | 4 | write data | `id u8, address u8, result u8` (1 = written; `uservo.py` `response_write_data` `<BBB`, `FSUS_WriteData` reads `content[2]`) |
//! | 10 | angle | `id u8, angle i16 (0.1°)` |
//! | 22 | monitor | `id u8, voltage u16 (mV), current u16 (mA), power u16 (mW), temperature u16 (raw ADC), status u8, angle i32 (0.1°), turns i16` |

use heapless::Vec;

use crate::wire::{PayloadWriter, Reader};
use crate::{DecodeError, MAX_READ_DATA_LEN, Message, RESPONSE_HEADER, Request, code};

/// Monitor data of one servo (code 22 response, 16 bytes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Monitor {
    /// Servo id.
    pub id: u8,
    /// Supply voltage, mV.
    pub voltage_mv: u16,
    /// Current, mA.
    pub current_ma: u16,
    /// Power, mW.
    pub power_mw: u16,
    /// Temperature as the raw NTC ADC value (the SDK converts it with
    /// `1 / (ln(t / (4096 − t)) / 3435 + 1 / 298.15) − 273.15` °C).
    pub temperature_raw: u16,
    /// Status bits (bit 0: executing a command, 1: command error, 2: stall,
    /// 3/4: voltage high/low, 5: current, 6: power, 7: temperature).
    pub status: u8,
    /// Angle, 0.1° (multi-turn capable).
    pub angle_tenths_deg: i32,
    /// Full turns.
    pub turns: i16,
}

/// One data-table entry (code 3 response).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ReadData {
    /// Servo id.
    pub id: u8,
    /// Data-table address.
    pub address: u8,
    /// The entry's bytes (little-endian values).
    pub data: Vec<u8, MAX_READ_DATA_LEN>,
}

/// The answer to a write (code 4 response, 3 bytes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WriteResult {
    /// Servo id (the id the request addressed).
    pub id: u8,
    /// Data-table address written.
    pub address: u8,
    /// The servo's result byte: 1 when the value was written.
    pub result: u8,
}

impl WriteResult {
    /// Whether the servo reports the value written.
    pub fn succeeded(&self) -> bool {
        self.result == 1
    }
}

/// A response frame (servo → controller).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Response {
    /// Code 1: servo `id` is there.
    Ping {
        /// Servo id.
        id: u8,
    },
    /// Code 10: the servo's angle.
    Angle {
        /// Servo id.
        id: u8,
        /// Angle, 0.1°.
        angle_tenths_deg: i16,
    },
    /// Code 22: monitor data.
    Monitor(Monitor),
    /// Code 3: a data-table entry.
    ReadData(ReadData),
    /// Code 4: the result of a write.
    WriteData(WriteResult),
}

impl Response {
    /// Id of the answering servo.
    pub fn id(&self) -> u8 {
        match self {
            Self::Ping { id } | Self::Angle { id, .. } => *id,
            Self::Monitor(m) => m.id,
            Self::ReadData(d) => d.id,
            Self::WriteData(w) => w.id,
        }
    }

    /// Whether this is the answer to `request` (same kind, same servo, and
    /// for read and write data the same address).
    pub fn answers(&self, request: &Request) -> bool {
        match (self, request) {
            (Self::Ping { id }, Request::Ping { id: want })
            | (Self::Angle { id, .. }, Request::QueryAngle { id: want }) => id == want,
            (Self::Monitor(m), Request::QueryMonitor { id: want }) => m.id == *want,
            (Self::ReadData(d), Request::ReadData { id, address }) => {
                d.id == *id && d.address == *address
            }
            (Self::WriteData(w), Request::WriteData { id, address, .. }) => {
                w.id == *id && w.address == *address
            }
            _ => false,
        }
    }
}

impl Message for Response {
    const HEADER: [u8; 2] = RESPONSE_HEADER;

    /// Command code of the frame.
    fn code(&self) -> u8 {
        match self {
            Self::Ping { .. } => code::PING,
            Self::Angle { .. } => code::QUERY_ANGLE,
            Self::Monitor(_) => code::QUERY_MONITOR,
            Self::ReadData(_) => code::READ_DATA,
            Self::WriteData(_) => code::WRITE_DATA,
        }
    }

    fn write_payload(&self, w: &mut PayloadWriter) {
        match self {
            Self::Ping { id } => w.u8(*id),
            Self::Angle {
                id,
                angle_tenths_deg,
            } => {
                w.u8(*id);
                w.i16(*angle_tenths_deg);
            }
            Self::Monitor(m) => {
                w.u8(m.id);
                w.u16(m.voltage_mv);
                w.u16(m.current_ma);
                w.u16(m.power_mw);
                w.u16(m.temperature_raw);
                w.u8(m.status);
                w.i32(m.angle_tenths_deg);
                w.i16(m.turns);
            }
            Self::ReadData(d) => {
                w.u8(d.id);
                w.u8(d.address);
                w.bytes(&d.data);
            }
            Self::WriteData(r) => {
                w.u8(r.id);
                w.u8(r.address);
                w.u8(r.result);
            }
        }
    }

    fn payload_len(code: u8) -> Option<(usize, usize)> {
        match code {
            code::PING => Some((1, 1)),
            code::QUERY_ANGLE => Some((3, 3)),
            code::QUERY_MONITOR => Some((16, 16)),
            code::READ_DATA => Some((2, 2 + MAX_READ_DATA_LEN)),
            code::WRITE_DATA => Some((3, 3)),
            _ => None,
        }
    }

    fn parse(code: u8, payload: &[u8]) -> Result<Self, DecodeError> {
        let bad_len = DecodeError::BadLength {
            code,
            len: u8::try_from(payload.len()).unwrap_or(u8::MAX),
        };
        let mut r = Reader::new(payload);
        let response = match code {
            code::PING => Self::Ping {
                id: r.u8().ok_or(bad_len)?,
            },
            code::QUERY_ANGLE => Self::Angle {
                id: r.u8().ok_or(bad_len)?,
                angle_tenths_deg: r.i16().ok_or(bad_len)?,
            },
            code::QUERY_MONITOR => Self::Monitor(
                (|| {
                    Some(Monitor {
                        id: r.u8()?,
                        voltage_mv: r.u16()?,
                        current_ma: r.u16()?,
                        power_mw: r.u16()?,
                        temperature_raw: r.u16()?,
                        status: r.u8()?,
                        angle_tenths_deg: r.i32()?,
                        turns: r.i16()?,
                    })
                })()
                .ok_or(bad_len)?,
            ),
            code::READ_DATA => {
                let id = r.u8().ok_or(bad_len)?;
                let address = r.u8().ok_or(bad_len)?;
                let data = Vec::from_slice(r.rest()).map_err(|_| bad_len)?;
                r = Reader::new(&[]);
                Self::ReadData(ReadData { id, address, data })
            }
            code::WRITE_DATA => Self::WriteData(WriteResult {
                id: r.u8().ok_or(bad_len)?,
                address: r.u8().ok_or(bad_len)?,
                result: r.u8().ok_or(bad_len)?,
            }),
            _ => return Err(DecodeError::UnknownCode { code }),
        };
        r.end().ok_or(bad_len)?;
        Ok(response)
    }
}

#[cfg(test)]
mod tests;
