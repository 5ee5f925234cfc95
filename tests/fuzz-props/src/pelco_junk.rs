//! PELCO decoder properties against what the bus can carry between good
//! frames: an exact model of the byte accounting, and junk that must
//! change nothing.
//!
//! * [`model`]: the decoder's counts, frames and buffered tail equal a
//!   whole-input scan of the spec (at a sync byte, a whole frame of its
//!   dialect is a frame or a foreign frame, otherwise a bad checksum whose
//!   sync byte is dropped; any other byte outside a frame is discarded),
//!   so every byte is accounted for exactly once.
//! * [`junk_changes_nothing`]: good frames for the device with junk in
//!   between — garbage, frames with a wrong checksum (or PELCO-P ETX),
//!   truncated frames completed by line noise, frames for other addresses —
//!   give exactly the frames, and the session exactly the product
//!   commands, of the good frames alone; each piece of junk is counted
//!   where it belongs.

use laser_app::domain::PointCm;
use laser_app::pelco::{Request, Session, View};
use pelco::{Command, Counters, Decoder, Frame, Protocol};

use crate::Bytes;

/// The decoder's address in these checks.
const DEVICE: u8 = 1;

/// What a whole-input scan of the spec finds in `data`: the frames for
/// `DEVICE`, the counts, and how many bytes at the end wait for more.
pub fn model(data: &[u8]) -> (Vec<Frame>, Counters, usize) {
    let mut c = Counters::default();
    let mut frames = Vec::new();
    let mut i = 0;
    while i < data.len() {
        let Some(p) = Protocol::from_sync(data[i]) else {
            c.discarded_bytes += 1;
            i += 1;
            continue;
        };
        let Some(run) = data.get(i..i + p.frame_len()) else {
            return (frames, c, data.len() - i);
        };
        match Frame::parse(run) {
            Some(f) if f.address == p.wire_address(DEVICE) => {
                c.frames += 1;
                frames.push(f);
                i += p.frame_len();
            }
            Some(_) => {
                c.other_addresses += 1;
                i += p.frame_len();
            }
            None => {
                c.bad_checksums += 1;
                c.discarded_bytes += 1;
                i += 1;
            }
        }
    }
    (frames, c, 0)
}

/// The streaming decoder on `data` equals [`model`], and the counts add
/// up to the input's length.
pub fn check_model(data: &[u8]) -> Counters {
    let mut d = Decoder::new(DEVICE);
    let mut frames = Vec::new();
    d.decode(data, |f| frames.push(f));
    let (want, counts, tail) = model(data);
    assert_eq!(frames, want, "frames differ from the spec's scan");
    assert_eq!(d.counters(), counts, "counts differ from the spec's scan");
    assert_eq!(
        d.buffered(),
        tail,
        "buffered tail differs from the spec's scan"
    );
    counts
}

/// Kinds of junk put between good frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Junk {
    Garbage,
    WrongChecksum,
    Truncated,
    OtherAddress,
}

/// A byte that is no sync byte (`b`, or `b` with its low bit flipped).
fn not_sync(b: u8) -> u8 {
    if Protocol::from_sync(b).is_some() {
        b ^ 1
    } else {
        b
    }
}

/// A run of one frame's length that starts with `p`'s sync byte, has no
/// other sync byte and does not parse: first `keep` bytes of `frame`, then
/// `noise`, its last byte moved off the one value that would parse.
fn bad_run(frame: &Frame, keep: usize, noise: &mut Bytes<'_>) -> Vec<u8> {
    let mut run = frame.encode().as_slice().to_vec();
    for b in run.iter_mut().skip(keep.max(1)) {
        *b = noise.u8();
    }
    for b in run.iter_mut().skip(1) {
        *b = not_sync(*b);
    }
    let last = run.len() - 1;
    while Frame::parse(&run).is_some() {
        run[last] = not_sync(run[last].wrapping_add(2));
    }
    run
}

/// What [`junk_changes_nothing`] put in, for the corpus summary.
#[derive(Debug, Default, Clone, Copy)]
pub struct JunkSummary {
    /// Good frames.
    pub good: usize,
    /// Junk pieces of each kind: garbage, wrong checksum, truncated,
    /// other address.
    pub junk: [usize; 4],
}

/// Good frames from `data` with junk between them decode to the good
/// frames alone, give the session the same product commands, and each
/// piece of junk is counted.
pub fn junk_changes_nothing(data: &[u8]) -> JunkSummary {
    let mut g = Bytes::new(data);
    let (mut clean, mut dirty) = (Vec::new(), Vec::new());
    let mut expected = Counters::default();
    let mut summary = JunkSummary::default();
    while !g.is_empty() && summary.good < 16 {
        let p = if g.u8() & 1 == 0 {
            Protocol::D
        } else {
            Protocol::P
        };
        let good = Command::from_bytes(g.array()).frame(p, p.wire_address(DEVICE));
        let junk = match g.u8() % 5 {
            0 => Junk::Garbage,
            1 => Junk::WrongChecksum,
            2 => Junk::Truncated,
            3 => Junk::OtherAddress,
            _ => {
                // No junk before this frame.
                clean.extend_from_slice(good.encode().as_slice());
                dirty.extend_from_slice(good.encode().as_slice());
                summary.good += 1;
                continue;
            }
        };
        let piece = match junk {
            Junk::Garbage => {
                let n = usize::from(g.u8() % 16);
                (0..n).map(|_| not_sync(g.u8())).collect::<Vec<u8>>()
            }
            Junk::WrongChecksum => bad_run(&good, p.frame_len(), &mut g),
            Junk::Truncated => {
                let keep = 1 + usize::from(g.u8()) % (p.frame_len() - 1);
                bad_run(&good, keep, &mut g)
            }
            Junk::OtherAddress => {
                let mut other = g.u8();
                if other == p.wire_address(DEVICE) {
                    other = other.wrapping_add(1);
                }
                Command::from_bytes(g.array())
                    .frame(p, other)
                    .encode()
                    .as_slice()
                    .to_vec()
            }
        };
        match junk {
            Junk::Garbage => expected.discarded_bytes += piece.len() as u32,
            Junk::WrongChecksum | Junk::Truncated => {
                expected.bad_checksums += 1;
                expected.discarded_bytes += piece.len() as u32;
            }
            Junk::OtherAddress => expected.other_addresses += 1,
        }
        summary.junk[junk as usize] += 1;
        summary.good += 1;
        dirty.extend_from_slice(&piece);
        dirty.extend_from_slice(good.encode().as_slice());
        clean.extend_from_slice(good.encode().as_slice());
    }
    let decode = |bytes: &[u8]| {
        let mut d = Decoder::new(DEVICE);
        let mut frames = Vec::new();
        d.decode(bytes, |f| frames.push(f));
        (frames, d.counters(), d.buffered())
    };
    let (want, clean_counts, _) = decode(&clean);
    let (got, counts, buffered) = decode(&dirty);
    assert_eq!(got, want, "junk changed the frames");
    assert_eq!(buffered, 0, "junk left bytes buffered");
    expected.frames = clean_counts.frames;
    assert_eq!(counts, expected, "junk not counted where it belongs");
    assert_eq!(session(&got), session(&want), "junk changed the commands");
    summary
}

/// The session's requests for `frames`, the spot at a fixed point.
fn session(frames: &[Frame]) -> Vec<Request> {
    let mut s = Session::new();
    let mut out = Vec::new();
    for (i, f) in frames.iter().enumerate() {
        let view = View {
            now_ms: 10 * i as u64,
            at: Some(PointCm::new(3.0, -2.0)),
            oq_cm: 100.0,
        };
        s.on_frame(f, view, &mut |r| out.push(r));
    }
    out
}
