//! The prepared steps, in place: a step's plans (a few KB with its
//! stroke) are written once by the prep stage and used where they lie by
//! the refill, never copied in it.

use super::state::{PREP_DEPTH, Prepared};

/// Slots: the running step and [`PREP_DEPTH`] prepared ones.
const SLOTS: usize = PREP_DEPTH + 1;

/// A ring of prepared steps, oldest first (the motion pipeline's ring:
/// the running step is dropped where it lies, `Ring::drop_front`).
pub(in crate::galvo::scan) type StepRing = kinematics_core::ring::Ring<Prepared, SLOTS>;
