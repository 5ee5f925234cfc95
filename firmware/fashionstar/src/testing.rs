//! Test support (feature `testing`; always in this crate's own tests): the
//! one frame-building helper the known-answer, decoder and property tests
//! here, the simulated servos' tests and the fuzz properties share.

extern crate std;

use core::fmt::Debug;
use std::vec::Vec;

use crate::{MAX_FRAME_LEN, Message};

/// The frame of `message`, bytes: encodes it and checks that its length
/// is [`Message::encoded_len`]. Panics (fails the test) when the message
/// does not encode.
pub fn frame<M: Message + Debug>(message: &M) -> Vec<u8> {
    let mut out = [0u8; MAX_FRAME_LEN];
    let len = message
        .encode(&mut out)
        .unwrap_or_else(|e| panic!("{message:?}: a frame of at most MAX_FRAME_LEN bytes: {e:?}"));
    assert_eq!(len, message.encoded_len(), "{message:?}: encoded_len");
    out[..len].to_vec()
}
