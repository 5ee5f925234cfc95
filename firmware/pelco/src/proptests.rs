//! encode∘decode over generated commands and addresses, and arbitrary
//! bytes through the streaming decoder (the fuzz target's properties,
//! `tests/fuzz-props/src/pelco.rs`, go further on saved inputs).

extern crate std;
use std::vec::Vec;

use proptest::prelude::*;

use crate::{Command, Decoder, Frame, MAX_FRAME_LEN, Protocol};

fn protocol() -> impl Strategy<Value = Protocol> {
    prop_oneof![Just(Protocol::D), Just(Protocol::P)]
}

/// Any four bytes, as the command they decode to: every command the table
/// knows, reached through its own bytes.
fn command() -> impl Strategy<Value = Command> {
    any::<[u8; 4]>().prop_map(Command::from_bytes)
}

proptest! {
    #[test]
    fn command_frame_bytes_decode_back(p in protocol(), device in 1u8..=255, c in command()) {
        let address = p.wire_address(device);
        let frame = c.frame(p, address);
        let raw = frame.encode();
        prop_assert_eq!(raw.as_slice().len(), p.frame_len());
        prop_assert_eq!(Frame::parse(raw.as_slice()), Some(frame));
        prop_assert_eq!(Command::of(&frame), c);
        let mut d = Decoder::new(device);
        let mut got = Vec::new();
        d.decode(raw.as_slice(), |f| got.push(f));
        prop_assert_eq!(got, std::vec![frame]);
    }

    #[test]
    fn garbage_then_a_frame_never_panics_and_the_frame_is_found(
        garbage in proptest::collection::vec(any::<u8>(), 0..64),
        p in protocol(),
        c in command(),
    ) {
        let mut d = Decoder::new(7);
        d.decode(&garbage, |_| {});
        prop_assert!(d.buffered() < MAX_FRAME_LEN);
        // An idle line (zeros) flushes any torn frame.
        d.decode(&[0u8; 2 * MAX_FRAME_LEN], |_| {});
        prop_assert_eq!(d.buffered(), 0);
        let frame = c.frame(p, p.wire_address(7));
        let mut got = Vec::new();
        d.decode(frame.encode().as_slice(), |f| got.push(f));
        prop_assert_eq!(got, std::vec![frame]);
    }
}
