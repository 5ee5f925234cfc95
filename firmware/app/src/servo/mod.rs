//! The FashionStar servo bus: the servo task body ([`task`]) speaking the
//! `fashionstar` frame codec, and the plausibility filter of its angle
//! readings ([`plausibility`]).

pub mod plausibility;
pub mod task;
