//! The FashionStar servo bus: the frame codec ([`protocol`]) and the servo
//! task body ([`task`]).

pub mod plausibility;
pub mod protocol;
pub mod task;
