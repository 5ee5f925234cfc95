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
//! | 10 | angle | `id u8, angle i16 (0.1°)` |
//! | 22 | monitor | `id u8, voltage u16 (mV), current u16 (mA), power u16 (mW), temperature u16 (raw ADC), status u8, angle i32 (0.1°), turns i16` |

use heapless::Vec;

use super::decoder::Message;
use super::wire::{Reader, Writer, write_frame};
use super::{
    DecodeError, EncodeError, FRAME_OVERHEAD, MAX_FRAME_LEN, MAX_READ_DATA_LEN, RESPONSE_HEADER,
    Request, code,
};

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
}

impl Response {
    /// Command code of the frame.
    pub fn code(&self) -> u8 {
        match self {
            Self::Ping { .. } => code::PING,
            Self::Angle { .. } => code::QUERY_ANGLE,
            Self::Monitor(_) => code::QUERY_MONITOR,
            Self::ReadData(_) => code::READ_DATA,
        }
    }

    /// Id of the answering servo.
    pub fn id(&self) -> u8 {
        match self {
            Self::Ping { id } | Self::Angle { id, .. } => *id,
            Self::Monitor(m) => m.id,
            Self::ReadData(d) => d.id,
        }
    }

    /// Whether this is the answer to `request` (same kind, same servo, and
    /// for read data the same address).
    pub fn answers(&self, request: &Request) -> bool {
        match (self, request) {
            (Self::Ping { id }, Request::Ping { id: want })
            | (Self::Angle { id, .. }, Request::QueryAngle { id: want }) => id == want,
            (Self::Monitor(m), Request::QueryMonitor { id: want }) => m.id == *want,
            (Self::ReadData(d), Request::ReadData { id, address }) => {
                d.id == *id && d.address == *address
            }
            _ => false,
        }
    }

    fn payload(&self) -> Result<super::wire::Payload, EncodeError> {
        let mut w = Writer::new();
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
        write_frame(RESPONSE_HEADER, self.code(), &self.payload()?, out)
    }

    /// The frame as a vector.
    pub fn to_frame(&self) -> Result<Vec<u8, MAX_FRAME_LEN>, EncodeError> {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let len = self.encode(&mut buf)?;
        Vec::from_slice(buf.get(..len).unwrap_or(&[]))
            .map_err(|_| EncodeError::BufferTooSmall { needed: len })
    }
}

impl Message for Response {
    const HEADER: [u8; 2] = RESPONSE_HEADER;

    fn payload_len(code: u8) -> Option<(usize, usize)> {
        match code {
            code::PING => Some((1, 1)),
            code::QUERY_ANGLE => Some((3, 3)),
            code::QUERY_MONITOR => Some((16, 16)),
            code::READ_DATA => Some((2, 2 + MAX_READ_DATA_LEN)),
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
            _ => return Err(DecodeError::UnknownCode { code }),
        };
        r.end().ok_or(bad_len)?;
        Ok(response)
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        Response::encode(self, out)
    }
}

#[cfg(test)]
mod tests {
    //! Known-answer frames, checksums summed by hand in the comments.
    extern crate std;
    use super::*;
    use std::vec::Vec as StdVec;

    fn frame(r: &Response) -> StdVec<u8> {
        let f = r.to_frame().unwrap();
        assert_eq!(f.len(), r.encoded_len());
        f.to_vec()
    }

    #[test]
    fn ping() {
        // 05+1C+01+01+01 = 0x24
        assert_eq!(
            frame(&Response::Ping { id: 1 }),
            [0x05, 0x1C, 0x01, 0x01, 0x01, 0x24]
        );
    }

    #[test]
    fn angle() {
        // id 0, -12.3° = -123 = 0xFF85: 05+1C+0A+03+00+85+FF = 0x1B2 → 0xB2
        assert_eq!(
            frame(&Response::Angle {
                id: 0,
                angle_tenths_deg: -123
            }),
            [0x05, 0x1C, 0x0A, 0x03, 0x00, 0x85, 0xFF, 0xB2]
        );
    }

    #[test]
    fn monitor() {
        // id 1, 7400 mV (E8 1C), 120 mA (78 00), 888 mW (78 03),
        // raw 1854 (3E 07), status 1, angle 900 (84 03 00 00), turns 0:
        // 05+1C+16+10 = 47; +01 = 48; +E8+1C = 14C; +78+00 = 1C4;
        // +78+03 = 23F; +3E+07 = 284; +01 = 285; +84+03+00+00 = 30C;
        // +00+00 → 0x0C
        let m = Monitor {
            id: 1,
            voltage_mv: 7400,
            current_ma: 120,
            power_mw: 888,
            temperature_raw: 1854,
            status: 1,
            angle_tenths_deg: 900,
            turns: 0,
        };
        assert_eq!(
            frame(&Response::Monitor(m)),
            [
                0x05, 0x1C, 0x16, 0x10, 0x01, 0xE8, 0x1C, 0x78, 0x00, 0x78, 0x03, 0x3E, 0x07, 0x01,
                0x84, 0x03, 0x00, 0x00, 0x00, 0x00, 0x0C
            ]
        );
    }

    #[test]
    fn read_data() {
        // id 0, address 1 (voltage), 7400 mV (E8 1C):
        // 05+1C+03+04 = 28; +00+01 = 29; +E8+1C = 12D → 0x2D
        let d = ReadData {
            id: 0,
            address: 1,
            data: Vec::from_slice(&[0xE8, 0x1C]).unwrap(),
        };
        assert_eq!(
            frame(&Response::ReadData(d)),
            [0x05, 0x1C, 0x03, 0x04, 0x00, 0x01, 0xE8, 0x1C, 0x2D]
        );
    }

    #[test]
    fn answers_matches_kind_id_and_address() {
        let angle = Response::Angle {
            id: 1,
            angle_tenths_deg: 0,
        };
        assert!(angle.answers(&Request::QueryAngle { id: 1 }));
        assert!(!angle.answers(&Request::QueryAngle { id: 0 }));
        assert!(!angle.answers(&Request::Ping { id: 1 }));
        assert!(Response::Ping { id: 0 }.answers(&Request::Ping { id: 0 }));
        let d = Response::ReadData(ReadData {
            id: 0,
            address: 5,
            data: Vec::new(),
        });
        assert!(d.answers(&Request::ReadData { id: 0, address: 5 }));
        assert!(!d.answers(&Request::ReadData { id: 0, address: 4 }));
        assert_eq!(d.id(), 0);
        assert_eq!(d.code(), code::READ_DATA);
    }

    #[test]
    fn parse_rejects_wrong_lengths_and_codes() {
        assert!(matches!(
            Response::parse(code::QUERY_ANGLE, &[0, 0]),
            Err(DecodeError::BadLength { .. })
        ));
        assert!(matches!(
            Response::parse(code::PING, &[0, 0]),
            Err(DecodeError::BadLength { .. })
        ));
        assert_eq!(
            Response::parse(8, &[0]),
            Err(DecodeError::UnknownCode { code: 8 })
        );
        assert!(Response::parse(code::READ_DATA, &[0; 2 + MAX_READ_DATA_LEN]).is_ok());
        assert!(Response::parse(code::READ_DATA, &[0; 3 + MAX_READ_DATA_LEN]).is_err());
    }
}
