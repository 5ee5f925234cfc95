//! FashionStar frame codec: both streaming decoders on arbitrary bytes, and
//! encode∘decode on frames generated from the bytes.
//!
//! Properties, for the response decoder (firmware side) and the request
//! decoder (simulated servo side) alike:
//! * nothing panics and at most one frame ([`MAX_FRAME_LEN`] bytes) is
//!   ever buffered;
//! * the events do not depend on how the bytes are chunked (byte by byte
//!   with `feed`/`poll`, or in chunks with `decode`);
//! * every decoded frame re-encodes to bytes that occur, in order, in the
//!   input (the decoder invents nothing), and decodes alone to itself;
//! * after any garbage, one frame's worth of idle line (0x00) leaves the
//!   decoder empty, and the next valid frame decodes exactly (resync);
//! * generated requests and responses encode to a well-formed frame
//!   (header, code, length, checksum) of their stated length that decodes
//!   to the same message.

use std::collections::BTreeSet;
use std::fmt::Debug;

use fashionstar::testing::frame as encode;
use fashionstar::{
    MAX_FRAME_LEN, MAX_READ_DATA_LEN, MAX_SYNC_SERVOS, Message, Monitor, ReadData, Request,
    Response, SetAngle, SetAngleByInterval, SetAngleByVelocity, StreamDecoder, SyncEntries,
    WriteResult, checksum,
};

use crate::Bytes;

/// What one input exercised.
#[derive(Debug, Default)]
pub struct Summary {
    /// Kinds of response decoded from the raw bytes.
    pub responses: BTreeSet<&'static str>,
    /// Kinds of request decoded from the raw bytes.
    pub requests: BTreeSet<&'static str>,
    /// Decode errors reported (both directions).
    pub errors: usize,
}

/// Runs the codec properties on `data`; panics when one fails.
pub fn check(data: &[u8]) -> Summary {
    let mut summary = Summary::default();
    let mut gen_bytes = Bytes::new(data);
    let response = generated_response(&mut gen_bytes);
    let request = generated_request(&mut gen_bytes);
    round_trip(&response);
    round_trip(&request);
    for r in stream(data, &response, &mut summary.errors) {
        summary.responses.insert(response_kind(&r));
    }
    for r in stream(data, &request, &mut summary.errors) {
        summary.requests.insert(request_kind(&r));
    }
    summary
}

/// Name of a response variant.
pub fn response_kind(r: &Response) -> &'static str {
    match r {
        Response::Ping { .. } => "ping",
        Response::Angle { .. } => "angle",
        Response::Monitor(_) => "monitor",
        Response::ReadData(_) => "read-data",
        Response::WriteData(_) => "write-data",
    }
}

/// Name of a request variant (sync frames by inner command).
pub fn request_kind(r: &Request) -> &'static str {
    match r {
        Request::Ping { .. } => "ping",
        Request::ReadData { .. } => "read-data",
        Request::WriteData { .. } => "write-data",
        Request::SetAngle(_) => "set-angle",
        Request::Damping { .. } => "damping",
        Request::QueryAngle { .. } => "query-angle",
        Request::SetAngleByInterval(_) => "set-angle-by-interval",
        Request::SetAngleByVelocity(_) => "set-angle-by-velocity",
        Request::QueryMonitor { .. } => "query-monitor",
        Request::SyncSetAngle(_) => "sync-set-angle",
        Request::SyncSetAngleByInterval(_) => "sync-set-angle-by-interval",
        Request::SyncSetAngleByVelocity(_) => "sync-set-angle-by-velocity",
    }
}

/// A generated message encodes to a well-formed frame that decodes to it.
fn round_trip<M: Message + PartialEq + Debug + Clone>(m: &M) {
    // `encode` also checks the frame's length against `encoded_len`.
    let frame = encode(m);
    assert_eq!(frame[..2], M::HEADER, "{m:?}: header");
    assert_eq!(frame[2], m.code(), "{m:?}: code");
    assert_eq!(usize::from(frame[3]) + 5, frame.len(), "{m:?}: length byte");
    let (&sum, body) = frame.split_last().expect("non-empty frame");
    assert_eq!(checksum(body), sum, "{m:?}: checksum");
    let mut decoder = StreamDecoder::<M>::new();
    let events: Vec<_> = decoder.decode(&frame).collect();
    assert_eq!(events, [Ok(m.clone())], "{frame:02x?}");
    assert_eq!(decoder.buffered(), 0);
}

/// Decodes `data` both ways, checks the stream properties and returns the
/// frames decoded.
fn stream<M: Message + PartialEq + Debug + Clone>(
    data: &[u8],
    resync_frame: &M,
    errors: &mut usize,
) -> Vec<M> {
    // Byte by byte, draining every event as soon as it exists.
    let mut by_byte = StreamDecoder::<M>::new();
    let mut events = Vec::new();
    for &b in data {
        if let Some(event) = by_byte.feed(b) {
            events.push(event);
            while let Some(event) = by_byte.poll() {
                events.push(event);
            }
        }
        assert!(by_byte.buffered() <= MAX_FRAME_LEN, "buffer bound");
    }
    // In chunks whose sizes come from the data itself.
    let mut chunked = StreamDecoder::<M>::new();
    let mut chunk_events = Vec::new();
    let mut rest = data;
    let mut sizes = data.iter().rev().cycle();
    while !rest.is_empty() {
        let size = 1 + usize::from(*sizes.next().unwrap_or(&0)) % 64;
        let (chunk, tail) = rest.split_at(size.min(rest.len()));
        chunk_events.extend(chunked.decode(chunk));
        assert!(chunked.buffered() <= MAX_FRAME_LEN, "buffer bound");
        rest = tail;
    }
    assert_eq!(events, chunk_events, "events depend on chunking");
    assert_eq!(by_byte.buffered(), chunked.buffered());

    // Every frame occurs in the input, in order, and decodes alone to
    // itself.
    let mut frames = Vec::new();
    let mut from = 0;
    for event in events {
        let frame = match event {
            Ok(frame) => frame,
            Err(_) => {
                *errors += 1;
                continue;
            }
        };
        let bytes = encode(&frame);
        let at = data[from..]
            .windows(bytes.len())
            .position(|w| w == bytes.as_slice())
            .unwrap_or_else(|| panic!("{frame:?} ({bytes:02x?}) is not in the input after {from}"));
        from += at + bytes.len();
        let mut alone = StreamDecoder::<M>::new();
        let again: Vec<_> = alone.decode(&bytes).collect();
        assert_eq!(again, [Ok(frame.clone())], "{bytes:02x?}");
        frames.push(frame);
    }

    // Resync: an idle gap as long as a frame flushes whatever the garbage
    // left, and the next frame decodes exactly.
    let idle = [0u8; MAX_FRAME_LEN];
    let _ = by_byte.decode(&idle).count();
    assert_eq!(by_byte.buffered(), 0, "idle line after garbage");
    let frame = encode(resync_frame);
    let after: Vec<_> = by_byte.decode(&frame).collect();
    assert_eq!(after, [Ok(resync_frame.clone())], "frame after garbage");
    frames
}

fn set_angle(b: &mut Bytes<'_>) -> SetAngle {
    SetAngle {
        id: b.u8(),
        angle_tenths_deg: b.u16() as i16,
        interval_ms: b.u16(),
        power_mw: b.u16(),
    }
}

fn by_interval(b: &mut Bytes<'_>) -> SetAngleByInterval {
    SetAngleByInterval {
        id: b.u8(),
        angle_tenths_deg: b.u16() as i16,
        interval_ms: b.u16(),
        t_acc_ms: b.u16(),
        t_dec_ms: b.u16(),
        power_mw: b.u16(),
    }
}

fn by_velocity(b: &mut Bytes<'_>) -> SetAngleByVelocity {
    SetAngleByVelocity {
        id: b.u8(),
        angle_tenths_deg: b.u16() as i16,
        velocity_tenths_deg_s: b.u16(),
        t_acc_ms: b.u16(),
        t_dec_ms: b.u16(),
        power_mw: b.u16(),
    }
}

fn entries<T>(b: &mut Bytes<'_>, entry: fn(&mut Bytes<'_>) -> T) -> SyncEntries<T> {
    let count = usize::from(b.u8()) % (MAX_SYNC_SERVOS + 1);
    let mut out = SyncEntries::new();
    for _ in 0..count {
        if out.push(entry(b)).is_err() {
            unreachable!("count ≤ MAX_SYNC_SERVOS");
        }
    }
    out
}

/// A request of every kind the codec models, fields from the bytes.
fn generated_request(b: &mut Bytes<'_>) -> Request {
    match b.u8() % 12 {
        0 => Request::Ping { id: b.u8() },
        1 => Request::ReadData {
            id: b.u8(),
            address: b.u8(),
        },
        2 => Request::SetAngle(set_angle(b)),
        3 => Request::Damping {
            id: b.u8(),
            power_mw: b.u16(),
        },
        4 => Request::QueryAngle { id: b.u8() },
        5 => Request::SetAngleByInterval(by_interval(b)),
        6 => Request::SetAngleByVelocity(by_velocity(b)),
        7 => Request::QueryMonitor { id: b.u8() },
        8 => Request::SyncSetAngle(entries(b, set_angle)),
        9 => Request::SyncSetAngleByInterval(entries(b, by_interval)),
        10 => {
            let (id, address) = (b.u8(), b.u8());
            let len = 1 + usize::from(b.u8()) % MAX_READ_DATA_LEN;
            let mut data = heapless::Vec::new();
            for _ in 0..len {
                if data.push(b.u8()).is_err() {
                    unreachable!("len ≤ MAX_READ_DATA_LEN");
                }
            }
            Request::WriteData { id, address, data }
        }
        _ => Request::SyncSetAngleByVelocity(entries(b, by_velocity)),
    }
}

/// A response of every kind the codec models, fields from the bytes.
fn generated_response(b: &mut Bytes<'_>) -> Response {
    match b.u8() % 5 {
        0 => Response::Ping { id: b.u8() },
        3 => Response::WriteData(WriteResult {
            id: b.u8(),
            address: b.u8(),
            result: b.u8(),
        }),
        1 => Response::Angle {
            id: b.u8(),
            angle_tenths_deg: b.u16() as i16,
        },
        2 => Response::Monitor(Monitor {
            id: b.u8(),
            voltage_mv: b.u16(),
            current_ma: b.u16(),
            power_mw: b.u16(),
            temperature_raw: b.u16(),
            status: b.u8(),
            angle_tenths_deg: i32::from_le_bytes(b.array()),
            turns: b.u16() as i16,
        }),
        _ => {
            let id = b.u8();
            let address = b.u8();
            let len = usize::from(b.u8()) % (MAX_READ_DATA_LEN + 1);
            let mut data = heapless::Vec::new();
            for _ in 0..len {
                if data.push(b.u8()).is_err() {
                    unreachable!("len ≤ MAX_READ_DATA_LEN");
                }
            }
            Response::ReadData(ReadData { id, address, data })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_hidden_in_garbage_is_found_and_checked() {
        // Garbage, a false monitor header swallowing a real ping, more
        // garbage, then an angle response.
        let mut data = vec![0x00, 0x05, 0x1C, 0x16, 0x10, 0x01];
        data.extend([0x05, 0x1C, 0x01, 0x01, 0x00, 0x23]);
        data.extend([0x00; 11]);
        data.extend([0x05, 0x1C, 0x0A, 0x03, 0x01, 0x85, 0xFF, 0xB3]);
        let s = check(&data);
        assert_eq!(
            s.responses.iter().copied().collect::<Vec<_>>(),
            ["angle", "ping"]
        );
        assert!(s.errors >= 1, "the false header is reported");
        assert!(s.requests.is_empty());
    }
}
