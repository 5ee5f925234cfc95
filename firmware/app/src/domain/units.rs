//! Lengths in the board plane: the one place where centimetres (board
//! points, figures, the gimbal, the command line) and millimetres (the
//! galvo, its DAC range) are converted into each other.

/// Millimetres per centimetre.
pub const MM_PER_CM: f64 = 10.0;

/// A length of `cm` centimetres, in mm.
pub fn mm_from_cm(cm: f64) -> f64 {
    cm * MM_PER_CM
}

/// A length of `mm` millimetres, in cm.
pub fn cm_from_mm(mm: f64) -> f64 {
    mm / MM_PER_CM
}

/// A length of `cm` centimetres as the galvo takes it: mm, `f32`.
pub fn galvo_mm_from_cm(cm: f64) -> f32 {
    mm_from_cm(cm) as f32
}

/// The unit a figure's strokes are laid out in (see
/// [`Figure::stroke`](super::figure::Figure::stroke)): each length of the
/// figure is converted first, then the strokes are built from the
/// converted lengths.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// Board centimetres, `f64` (the gimbal interpolates in them).
    BoardCm,
    /// Board millimetres at the galvo's `f32` precision (the galvo's path
    /// planner takes them).
    GalvoMm,
}

impl Unit {
    /// A length of `cm` centimetres in this unit.
    pub fn from_cm(self, cm: f64) -> f64 {
        match self {
            Unit::BoardCm => cm,
            Unit::GalvoMm => f64::from(galvo_mm_from_cm(cm)),
        }
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    proptest! {
        #[test]
        fn centimetres_and_millimetres_are_inverse(cm in -400.0f64..400.0) {
            let back = cm_from_mm(mm_from_cm(cm));
            prop_assert!((back - cm).abs() <= 1e-13 * cm.abs().max(1.0));
            prop_assert_eq!(Unit::BoardCm.from_cm(cm), cm);
            prop_assert_eq!(Unit::GalvoMm.from_cm(cm), f64::from(galvo_mm_from_cm(cm)));
        }
    }

    #[test]
    fn a_centimetre_is_ten_millimetres() {
        assert_eq!(mm_from_cm(1.5), 15.0);
        assert_eq!(cm_from_mm(-20.0), -2.0);
        assert_eq!(galvo_mm_from_cm(1.3), 13.0f32);
        assert_eq!(Unit::GalvoMm.from_cm(1.3), 13.0);
    }
}
