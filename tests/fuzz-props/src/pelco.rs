//! PELCO-D / PELCO-P frame codec: the streaming decoder on arbitrary
//! bytes, and encode∘decode on a command generated from the bytes.
//!
//! Properties:
//! * nothing panics and less than one frame ([`MAX_FRAME_LEN`] bytes) is
//!   ever left buffered;
//! * the frames and counters do not depend on how the bytes are chunked;
//! * every delivered frame is for the decoder's device and re-encodes to
//!   bytes that occur, in order, in the input (the decoder invents
//!   nothing);
//! * every byte is accounted for, exactly as a whole-input scan of the
//!   spec counts it ([`crate::pelco_junk::model`]);
//! * garbage, wrong checksums, truncated frames and foreign frames between
//!   good frames change neither the frames nor the session's commands, and
//!   are counted ([`crate::pelco_junk::junk_changes_nothing`]);
//! * after any input, an idle line (zeros) empties the decoder and the
//!   next valid frame decodes exactly (resync);
//! * a generated command encodes to a well-formed frame of its dialect's
//!   length that decodes to the same command.

use std::collections::BTreeSet;

use pelco::{Command, Counters, Decoder, Frame, MAX_FRAME_LEN, Protocol};

use crate::Bytes;
use crate::pelco_junk::{JunkSummary, check_model, junk_changes_nothing};

/// What one input exercised.
#[derive(Debug, Default)]
pub struct Summary {
    /// Kinds of command decoded from the raw bytes (`D:stop`, `P:set-pan`…).
    pub commands: BTreeSet<String>,
    /// The decoder's counts over the raw bytes.
    pub counters: Counters,
    /// Good frames and junk the junk property built from the bytes.
    pub junk: JunkSummary,
}

/// Runs the codec properties on `data`; panics when one fails.
pub fn check(data: &[u8]) -> Summary {
    let mut gen_bytes = Bytes::new(data);
    let device = gen_bytes.u8().max(1);
    let protocol = if gen_bytes.u8() & 1 == 0 {
        Protocol::D
    } else {
        Protocol::P
    };
    let generated = Command::from_bytes(gen_bytes.array());
    round_trip(protocol, device, generated);

    // The raw input, to device 1 (the default address), byte by byte.
    let mut whole = Decoder::new(1);
    let mut frames = Vec::new();
    for &b in data {
        if let Some(f) = whole.feed(b) {
            frames.push(f);
        }
        assert!(
            whole.buffered() < MAX_FRAME_LEN,
            "a whole frame stayed buffered"
        );
    }
    let counters = whole.counters();
    assert_eq!(counters.frames as usize, frames.len());

    // Chunking does not matter.
    let mut chunked = Decoder::new(1);
    let mut again = Vec::new();
    for chunk in data.chunks(3) {
        chunked.decode(chunk, |f| again.push(f));
    }
    assert_eq!(frames, again, "chunking changed the frames");
    assert_eq!(chunked.counters(), counters, "chunking changed the counts");

    // Nothing invented: each frame is for us, and its bytes appear in order.
    let mut rest = data;
    for f in &frames {
        assert_eq!(
            f.address,
            f.protocol.wire_address(1),
            "foreign frame delivered"
        );
        let raw = f.encode();
        let at = find(rest, raw.as_slice()).expect("delivered frame not in the input");
        rest = &rest[at + raw.as_slice().len()..];
    }

    // Every byte accounted for, as the spec's scan counts it.
    assert_eq!(check_model(data), counters);
    let junk = junk_changes_nothing(data);

    // Resync: idle line, then a valid frame.
    whole.decode(&[0u8; 2 * MAX_FRAME_LEN], |_| {});
    assert_eq!(whole.buffered(), 0, "idle line left bytes buffered");
    let next = generated.frame(protocol, protocol.wire_address(1));
    let mut got = Vec::new();
    whole.decode(next.encode().as_slice(), |f| got.push(f));
    assert_eq!(got, vec![next], "valid frame after resync not decoded");

    Summary {
        commands: frames
            .iter()
            .map(|f| format!("{}:{}", f.protocol.name(), Command::of(f).name()))
            .collect(),
        counters,
        junk,
    }
}

/// A generated command to `device` encodes to one well-formed frame that
/// parses and decodes back to it.
fn round_trip(protocol: Protocol, device: u8, command: Command) {
    let frame = command.frame(protocol, protocol.wire_address(device));
    let raw = frame.encode();
    assert_eq!(raw.as_slice().len(), protocol.frame_len());
    assert_eq!(raw.as_slice()[0], protocol.sync());
    assert_eq!(Frame::parse(raw.as_slice()), Some(frame), "encode∘parse");
    assert_eq!(Command::of(&frame), command, "command∘frame");
    assert_eq!(Command::of(&frame).to_bytes(), command.to_bytes());
    let mut d = Decoder::new(device);
    let mut got = Vec::new();
    d.decode(raw.as_slice(), |f| got.push(f));
    assert_eq!(got, vec![frame], "generated frame not decoded");
}

/// Index of the first occurrence of `needle` in `hay`.
fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}
