//! Known-answer frames, checksums summed by hand in the comments.
use super::*;
use crate::testing::frame;

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

/// What the SDK's `response_write_data` unpacks (`<BBB`: id, address,
/// result; `FSUS_WriteData` reads the result at `content[2]`).
#[test]
fn write_data() {
    // id 0, address 34 (0x22), result 1: 05+1C+04+03 = 28; +00+22 = 4A; +01 = 4B
    let ok = Response::WriteData(WriteResult {
        id: 0,
        address: 34,
        result: 1,
    });
    assert_eq!(frame(&ok), [0x05, 0x1C, 0x04, 0x03, 0x00, 0x22, 0x01, 0x4B]);
    // result 0 (refused): 4A
    let refused = Response::WriteData(WriteResult {
        id: 0,
        address: 34,
        result: 0,
    });
    assert_eq!(
        frame(&refused),
        [0x05, 0x1C, 0x04, 0x03, 0x00, 0x22, 0x00, 0x4A]
    );
    let Response::WriteData(w) = ok else {
        unreachable!()
    };
    assert!(w.succeeded());
    assert!(ok.answers(&Request::set_servo_id(0, 1)));
    assert!(!ok.answers(&Request::set_servo_id(1, 0)));
    assert!(!ok.answers(&Request::ReadData { id: 0, address: 34 }));
}
