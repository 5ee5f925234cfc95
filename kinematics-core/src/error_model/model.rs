//! The error quadratics and their compensation (SPEC §5): the items the
//! fit and the model's users share.

use crate::error::Error;
use crate::frames::{BoardPoint, PointMm};
use crate::numeric::finite;

/// Number of coefficients per axis.
pub const N_COEF: usize = 6;
/// Largest |value| of a measured position or error accepted by [`fit`](super::fit),
/// mm (10 m: far beyond any board, far below where `x²` loses the
/// precision of a millimetre-scale fit).
pub const MAX_MEASURED_MM: f64 = 10_000.0;
/// Largest |coefficient| the firmware accepts per coefficient (its `set
/// err.*` ranges): c0 ±100 mm (a 10 cm offset is a mis-mounted board),
/// c1/c2 ±1 mm/mm (100 % scale error), c3..c5 ±0.01 1/mm (100 mm of error
/// 100 mm from the centre).
pub const COEF_LIMITS: [f64; N_COEF] = [100.0, 1.0, 1.0, 0.01, 0.01, 0.01];
/// Most fixed-point iterations [`ErrorModel::compensate`] takes.
pub const MAX_ITERATIONS: u32 = 100;
/// Relative residual at which compensation stops: `|c + Δ(c) − target|`
/// ≤ `COMPENSATION_TOL · max(1 mm, |target|)`.
pub const COMPENSATION_TOL: f64 = 1e-10;

/// One axis' error quadratic, coefficients in the order
/// 1, x, y, x², xy, y² (mm, mm/mm, mm/mm²).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Quadratic {
    /// `[c0, c1, c2, c3, c4, c5]`.
    pub coef: [f64; N_COEF],
}

impl Quadratic {
    /// The quadratic with these coefficients.
    pub const fn new(coef: [f64; N_COEF]) -> Self {
        Self { coef }
    }

    /// Δ (mm) at `(x_mm, y_mm)` (mm).
    ///
    /// Errors: [`Error::NonFinite`] (input, coefficient or overflowing result).
    pub fn eval(&self, x_mm: f64, y_mm: f64) -> Result<f64, Error> {
        finite(x_mm, "x_mm")?;
        finite(y_mm, "y_mm")?;
        if !self.coef.iter().all(|c| c.is_finite()) {
            return Err(Error::NonFinite {
                what: "error-model coefficient",
            });
        }
        Ok(finite(self.value(x_mm, y_mm), "error-model value")?)
    }

    /// Δ without checks (callers validated), Horner-style.
    #[inline]
    pub(crate) fn value(&self, x_mm: f64, y_mm: f64) -> f64 {
        let [c0, c1, c2, c3, c4, c5] = self.coef;
        c0 + x_mm * (c1 + c3 * x_mm + c4 * y_mm) + y_mm * (c2 + c5 * y_mm)
    }
}

/// The fitted error of both axes. `Copy`; [`Default`] is the zero model
/// (no correction).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ErrorModel {
    /// Error of board x, mm.
    pub dx: Quadratic,
    /// Error of board y, mm.
    pub dy: Quadratic,
}

impl ErrorModel {
    /// The model with x coefficients `dx` and y coefficients `dy` (mm).
    pub const fn new(dx: [f64; N_COEF], dy: [f64; N_COEF]) -> Self {
        Self {
            dx: Quadratic::new(dx),
            dy: Quadratic::new(dy),
        }
    }

    fn check(&self) -> Result<(), Error> {
        if self
            .dx
            .coef
            .iter()
            .chain(self.dy.coef.iter())
            .all(|c| c.is_finite())
        {
            Ok(())
        } else {
            Err(Error::NonFinite {
                what: "error-model coefficient",
            })
        }
    }

    /// The error `(Δx, Δy)` (mm) at commanded point `p` (mm).
    ///
    /// Errors: [`Error::NonFinite`].
    pub fn error_at(&self, p: PointMm) -> Result<PointMm, Error> {
        self.check()?;
        p.check_finite()?;
        PointMm {
            x_mm: self.dx.value(p.x_mm, p.y_mm),
            y_mm: self.dy.value(p.x_mm, p.y_mm),
        }
        .check_finite()
    }

    /// Where the spot lands (mm) for commanded point `commanded` (mm):
    /// `commanded + Δ(commanded)`.
    ///
    /// Errors: [`Error::NonFinite`].
    pub fn predict(&self, commanded: PointMm) -> Result<PointMm, Error> {
        let e = self.error_at(commanded)?;
        PointMm {
            x_mm: commanded.x_mm + e.x_mm,
            y_mm: commanded.y_mm + e.y_mm,
        }
        .check_finite()
    }

    /// The commanded point (mm) whose predicted spot is `target` (mm): the
    /// fixed point of `c ← target − Δ(c)`, iterated until
    /// `|c + Δ(c) − target|` ≤ [`COMPENSATION_TOL`]`·max(1, |target|)` mm
    /// (so well within 1e-6 mm). Converges when Δ changes by less than the
    /// change in c (|∇Δ| < 1) near the target, as any plausible error
    /// model does.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::NotConverged`].
    pub fn compensate(&self, target: PointMm) -> Result<PointMm, Error> {
        self.check()?;
        target.check_finite()?;
        let tol = COMPENSATION_TOL * crate::numeric::hypot(target.x_mm, target.y_mm).max(1.0);
        let mut c = target;
        for _ in 0..MAX_ITERATIONS {
            let ex = self.dx.value(c.x_mm, c.y_mm);
            let ey = self.dy.value(c.x_mm, c.y_mm);
            // Residual of the current command.
            let rx = c.x_mm + ex - target.x_mm;
            let ry = c.y_mm + ey - target.y_mm;
            let res = crate::numeric::hypot(rx, ry);
            if !res.is_finite() {
                return Err(Error::NotConverged);
            }
            if res <= tol {
                return Ok(c);
            }
            c = PointMm {
                x_mm: target.x_mm - ex,
                y_mm: target.y_mm - ey,
            };
        }
        Err(Error::NotConverged)
    }

    /// [`compensate`](Self::compensate) for board points in cm.
    ///
    /// Errors: as [`compensate`](Self::compensate).
    pub fn compensate_board(&self, target: BoardPoint) -> Result<BoardPoint, Error> {
        Ok(self.compensate(target.check_finite()?.to_mm())?.to_cm())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn eval_hand_computed() {
        let q = Quadratic::new([1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        // 1 + 2·2 + 3·(−1) + 4·4 + 5·(−2) + 6·1 = 14.
        assert_eq!(q.eval(2.0, -1.0), Ok(14.0));
        assert_eq!(
            q.eval(f64::NAN, 0.0),
            Err(Error::NonFinite { what: "x_mm" })
        );
        assert_eq!(
            q.eval(1e200, 1e200),
            Err(Error::NonFinite {
                what: "error-model value"
            })
        );
        let bad = Quadratic::new([0.0, f64::INFINITY, 0.0, 0.0, 0.0, 0.0]);
        assert!(bad.eval(0.0, 0.0).is_err());
    }

    #[test]
    fn zero_model_changes_nothing() {
        let m = ErrorModel::default();
        let p = PointMm::new(12.5, -40.0);
        assert_eq!(m.predict(p).unwrap(), p);
        assert_eq!(m.compensate(p).unwrap(), p);
    }

    #[test]
    fn constant_offset_is_subtracted() {
        let m = ErrorModel::new(
            [0.5, 0.0, 0.0, 0.0, 0.0, 0.0],
            [-0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
        );
        let c = m.compensate(PointMm::new(10.0, 10.0)).unwrap();
        assert_eq!(c, PointMm::new(9.5, 10.2));
        let b = m.compensate_board(BoardPoint::new(1.0, 1.0)).unwrap();
        assert!((b.x_cm - 0.95).abs() < 1e-15 && (b.y_cm - 1.02).abs() < 1e-15);
    }

    #[test]
    fn linear_scale_error_has_the_closed_form_inverse() {
        // Δx = 0.01·x: the spot lands at 1.01·c, so c = target / 1.01.
        let m = ErrorModel::new([0.0, 0.01, 0.0, 0.0, 0.0, 0.0], [0.0; 6]);
        let c = m.compensate(PointMm::new(101.0, 7.0)).unwrap();
        assert!((c.x_mm - 100.0).abs() < 1e-8);
        assert_eq!(c.y_mm, 7.0);
    }

    #[test]
    fn divergent_and_invalid_models_are_errors() {
        // Δx = 2x: fixed-point iteration c ← t − 2c diverges.
        let m = ErrorModel::new([0.0, 2.0, 0.0, 0.0, 0.0, 0.0], [0.0; 6]);
        assert_eq!(
            m.compensate(PointMm::new(1.0, 0.0)),
            Err(Error::NotConverged)
        );
        // Δx = −x makes every command land on 0: no command reaches 1.
        let m = ErrorModel::new([0.0, -1.0, 0.0, 0.0, 0.0, 0.0], [0.0; 6]);
        assert_eq!(
            m.compensate(PointMm::new(1.0, 0.0)),
            Err(Error::NotConverged)
        );
        let m = ErrorModel::new([f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0; 6]);
        assert!(matches!(
            m.predict(PointMm::new(0.0, 0.0)),
            Err(Error::NonFinite { .. })
        ));
        let m = ErrorModel::default();
        assert_eq!(
            m.compensate(PointMm::new(f64::INFINITY, 0.0)),
            Err(Error::NonFinite { what: "x_mm" })
        );
        let m = ErrorModel::new([0.0, 0.0, 0.0, 1e300, 0.0, 0.0], [0.0; 6]);
        assert!(m.predict(PointMm::new(1e10, 0.0)).is_err());
    }

    /// Coefficients of a plausible model: ≤ 2 mm offset, ≤ 2 % scale,
    /// curvature ≤ 1 mm over ±200 mm — |∇Δ| well below 1.
    fn model() -> impl Strategy<Value = ErrorModel> {
        let axis = (
            -2.0f64..2.0,
            -0.02f64..0.02,
            -0.02f64..0.02,
            -2.5e-5f64..2.5e-5,
            -2.5e-5f64..2.5e-5,
            -2.5e-5f64..2.5e-5,
        )
            .prop_map(|(a, b, c, d, e, f)| [a, b, c, d, e, f]);
        (axis.clone(), axis).prop_map(|(dx, dy)| ErrorModel::new(dx, dy))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        #[test]
        fn compensate_then_predict_lands_on_target(
            m in model(), x in -200.0f64..200.0, y in -200.0f64..200.0,
        ) {
            let target = PointMm::new(x, y);
            let c = m.compensate(target).unwrap();
            let landed = m.predict(c).unwrap();
            prop_assert!(crate::numeric::hypot(landed.x_mm - x, landed.y_mm - y) <= 1e-6);
        }

        #[test]
        fn predict_then_compensate_recovers_the_command(
            m in model(), x in -200.0f64..200.0, y in -200.0f64..200.0,
        ) {
            let c = PointMm::new(x, y);
            let back = m.compensate(m.predict(c).unwrap()).unwrap();
            prop_assert!(crate::numeric::hypot(back.x_mm - x, back.y_mm - y) <= 1e-6);
        }
    }
}
