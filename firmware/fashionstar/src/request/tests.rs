//! Known-answer frames: each expected frame is spelled out from the
//! layout, with the checksum summed by hand in the comment.
extern crate std;
use super::*;
use crate::testing::frame;
use crate::{EncodeError, MAX_FRAME_LEN, MAX_SYNC_SERVOS};

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

/// What the SDK's `write_data(servo_id, 34, bytes([new_id]))` sends
/// (`Packet.pack(4, ustruct.pack('<BB', servo_id, 34) + content)`;
/// `FSUS_WriteData` builds the same buffer).
#[test]
fn write_data_servo_id() {
    // id 0 → 1: 5E (12+4C) +04+03 = 65; +00+22 = 87; +01 = 88
    assert_eq!(
        frame(&Request::set_servo_id(0, 1)),
        [0x12, 0x4C, 0x04, 0x03, 0x00, 0x22, 0x01, 0x88]
    );
    // id 5 → 254: 65 +05 = 6A; +22 = 8C; +FE = 18A → 0x8A
    assert_eq!(
        frame(&Request::set_servo_id(5, 254)),
        [0x12, 0x4C, 0x04, 0x03, 0x05, 0x22, 0xFE, 0x8A]
    );
    let r = Request::set_servo_id(0, 1);
    assert_eq!(r.id(), Some(0));
    assert!(r.expects_response());
    assert_eq!(r.motion_for(0), None);
}

#[test]
fn write_data_of_two_bytes() {
    // id 1, address 38 (0x26), value 0x1234 little-endian (34 12):
    // 5E +04+04 = 66; +01+26 = 8D; +34+12 = D3
    let r = Request::WriteData {
        id: 1,
        address: 38,
        data: Vec::from_slice(&[0x34, 0x12]).unwrap(),
    };
    assert_eq!(
        frame(&r),
        [0x12, 0x4C, 0x04, 0x04, 0x01, 0x26, 0x34, 0x12, 0xD3]
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
    let r =
        Request::SyncSetAngleByVelocity(SyncEntries::from_slice(&[full; MAX_SYNC_SERVOS]).unwrap());
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

#[test]
fn motion_for_picks_the_servos_own_command() {
    let a = |id, angle_tenths_deg| SetAngle {
        id,
        angle_tenths_deg,
        interval_ms: 100,
        power_mw: 0,
    };
    let sync = Request::sync_set_angle(&[a(0, 10), a(1, 20), a(1, 30)]).unwrap();
    assert_eq!(sync.motion_for(1), Some(MotionCommand::SetAngle(a(1, 20))));
    assert_eq!(sync.motion_for(2), None);
    let single = Request::SetAngle(a(3, 40));
    assert_eq!(
        single.motion_for(3),
        Some(MotionCommand::SetAngle(a(3, 40)))
    );
    assert_eq!(single.motion_for(0), None);
    let v = SetAngleByVelocity {
        id: 1,
        angle_tenths_deg: 5,
        velocity_tenths_deg_s: 100,
        t_acc_ms: 20,
        t_dec_ms: 20,
        power_mw: 0,
    };
    let sync = Request::SyncSetAngleByVelocity(SyncEntries::from_slice(&[v]).unwrap());
    assert_eq!(
        sync.motion_for(1),
        Some(MotionCommand::SetAngleByVelocity(v))
    );
    let i = SetAngleByInterval {
        id: 2,
        angle_tenths_deg: 5,
        interval_ms: 100,
        t_acc_ms: 20,
        t_dec_ms: 20,
        power_mw: 0,
    };
    assert_eq!(
        Request::SetAngleByInterval(i).motion_for(2),
        Some(MotionCommand::SetAngleByInterval(i))
    );
    let damping = Request::Damping {
        id: 4,
        power_mw: 500,
    };
    assert_eq!(
        damping.motion_for(4),
        Some(MotionCommand::Damping { power_mw: 500 })
    );
    assert_eq!(damping.motion_for(1), None);
    assert_eq!(Request::QueryAngle { id: 4 }.motion_for(4), None);
}
