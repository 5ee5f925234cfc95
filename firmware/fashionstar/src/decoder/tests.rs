extern crate std;
use std::vec::Vec;

use super::*;
use crate::SetAngle;

fn all<M: Message>(d: &mut StreamDecoder<M>, bytes: &[u8]) -> Vec<Result<M, DecodeError>> {
    d.decode(bytes).collect()
}

const PING0: [u8; 6] = [0x05, 0x1C, 0x01, 0x01, 0x00, 0x23];
const ANGLE1: [u8; 8] = [0x05, 0x1C, 0x0A, 0x03, 0x01, 0x85, 0xFF, 0xB3];

#[test]
fn byte_by_byte() {
    let mut d = ResponseDecoder::new();
    let mut out = Vec::new();
    for &b in PING0.iter().chain(&ANGLE1) {
        if let Some(ev) = d.feed(b) {
            out.push(ev);
        }
    }
    assert_eq!(
        out,
        [
            Ok(Response::Ping { id: 0 }),
            Ok(Response::Angle {
                id: 1,
                angle_tenths_deg: -123
            })
        ]
    );
    assert_eq!(d.buffered(), 0);
}

#[test]
fn garbage_before_between_and_split_header() {
    let mut d = ResponseDecoder::new();
    assert_eq!(all(&mut d, &[0x00, 0xFF, 0x05, 0x05]), []);
    // The last 0x05 may start a header: it is kept.
    assert_eq!(d.buffered(), 1);
    let mut rest = PING0[1..].to_vec();
    rest.extend([0x1C, 0x77]);
    rest.extend(ANGLE1);
    let out = all(&mut d, &rest);
    assert_eq!(out.len(), 2);
    assert_eq!(out[0], Ok(Response::Ping { id: 0 }));
    assert!(out[1].is_ok());
}

#[test]
fn bad_checksum_then_rescan_finds_hidden_frame() {
    // A false header announcing a 16-byte monitor payload swallows a
    // real ping; the false frame fails its checksum, and the rescan from
    // the byte after the false header finds the ping.
    let mut bytes = std::vec![0x05, 0x1C, 0x16, 0x10, 0x01];
    bytes.extend(PING0);
    bytes.extend([0x00; 11]);
    let mut d = ResponseDecoder::new();
    let out = all(&mut d, &bytes);
    assert!(matches!(
        out[0],
        Err(DecodeError::BadChecksum { code: 22, .. })
    ));
    assert_eq!(out[1], Ok(Response::Ping { id: 0 }));
    assert_eq!(out.len(), 2);
}

#[test]
fn feed_leaves_hidden_frame_for_poll() {
    let mut bytes = std::vec![0x05, 0x1C, 0x16, 0x10];
    bytes.extend(PING0);
    bytes.extend([0x00; 11]);
    let mut d = ResponseDecoder::new();
    let mut events = Vec::new();
    for &b in &bytes {
        if let Some(ev) = d.feed(b) {
            events.push(ev);
            while let Some(ev) = d.poll() {
                events.push(ev);
            }
        }
    }
    assert!(events[0].is_err());
    assert_eq!(events[1], Ok(Response::Ping { id: 0 }));
}

#[test]
fn bad_length_is_reported_at_the_length_byte() {
    let mut d = ResponseDecoder::new();
    assert_eq!(all(&mut d, &[0x05, 0x1C, 0x0A]), []);
    assert_eq!(
        d.feed(0x02),
        Some(Err(DecodeError::BadLength { code: 10, len: 2 }))
    );
    // Extended-length marker 0xFF.
    assert_eq!(
        all(&mut d, &[0x05, 0x1C, 0x19, 0xFF]),
        [Err(DecodeError::BadLength {
            code: 25,
            len: 0xFF
        })]
    );
    assert_eq!(all(&mut d, &PING0), [Ok(Response::Ping { id: 0 })]);
}

#[test]
fn unknown_code_frame_is_skipped_whole() {
    // A code-5 frame (the SDK's unused "query servo info") is intact but
    // not modelled: 05+1C+05+03+00+21+01 = 0x4B.
    let mut bytes = std::vec![0x05, 0x1C, 0x05, 0x03, 0x00, 0x21, 0x01, 0x4B];
    bytes.extend(PING0);
    let mut d = ResponseDecoder::new();
    assert_eq!(
        all(&mut d, &bytes),
        [
            Err(DecodeError::UnknownCode { code: 5 }),
            Ok(Response::Ping { id: 0 })
        ]
    );
}

#[test]
fn requests_decode_too_and_reset_forgets() {
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
    let f = r.to_frame().unwrap();
    let mut d = RequestDecoder::new();
    assert_eq!(all(&mut d, &f[..10]), []);
    d.reset();
    assert_eq!(all(&mut d, &f[10..]), []);
    assert_eq!(all(&mut d, &f), [Ok(r)]);
    // Response bytes on the line are ignored by the request decoder.
    assert_eq!(all(&mut d, &PING0), []);
}

#[test]
fn push_without_poll_stays_bounded() {
    let mut d = ResponseDecoder::new();
    for _ in 0..1000 {
        d.push(0x05);
    }
    assert!(d.buffered() <= MAX_FRAME_LEN);
    let _ = all(&mut d, &[]);
}
