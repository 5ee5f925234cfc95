//! The FashionStar servo bus: the servo task body ([`task`]) speaking the
//! `fashionstar` frame codec, what it and the sequencer exchange
//! ([`link`], [`id_set`]), and the plausibility filter of its angle
//! readings ([`plausibility`]).

pub mod id_set;
pub mod link;
pub mod plausibility;
pub mod task;
