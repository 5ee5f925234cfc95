//! The galvo's geometry, its DAC axes and the exact map between them
//! (SPEC §4.5; [`super`] explains the mapping).

use crate::error::Error;
use crate::frames::PointMm;
use crate::numeric::finite;
use crate::real::Real;

/// Highest code of the 12-bit DAC.
pub const DAC_MAX_CODE: u16 = 4095;
/// SPEC default distance Y mirror → board, mm.
pub const DEFAULT_D_MM: f64 = 400.0;
/// SPEC default mirror separation, mm.
pub const DEFAULT_E_MM: f64 = 10.0;
/// SPEC default mechanical half range mapped onto the DAC span, degrees.
pub const DEFAULT_HALF_RANGE_DEG: f64 = 12.5;
/// Mid-scale of the 12-bit DAC (code for 0°, before rounding).
pub const DAC_MID_CODE: f64 = 2047.5;

/// Mechanical mirror angles, radians (the beam turns by twice these).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MirrorAngles<F = f64> {
    /// X mirror (first), mechanical radians.
    pub x_rad: F,
    /// Y mirror (second), mechanical radians.
    pub y_rad: F,
}

/// Mirror geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GalvoGeometry<F = f64> {
    /// Distance from the Y mirror to the board, mm (> 0).
    pub d_mm: F,
    /// Separation of the X and Y mirrors, mm (≥ 0).
    pub e_mm: F,
}

impl<F: Real> Default for GalvoGeometry<F> {
    /// SPEC defaults: d = 400 mm, e = 10 mm.
    fn default() -> Self {
        Self {
            d_mm: F::from_f64(DEFAULT_D_MM),
            e_mm: F::from_f64(DEFAULT_E_MM),
        }
    }
}

impl<F: Real> GalvoGeometry<F> {
    #[inline]
    pub(crate) fn validate(&self) -> Result<(), Error> {
        if self.d_mm <= F::ZERO || !self.d_mm.is_finite() {
            return Err(Error::InvalidConfig {
                what: "galvo d_mm must be finite and > 0",
            });
        }
        if self.e_mm < F::ZERO || !self.e_mm.is_finite() {
            return Err(Error::InvalidConfig {
                what: "galvo e_mm must be finite and >= 0",
            });
        }
        Ok(())
    }

    /// Mirror angles that put the spot on board point `p` (mm).
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`].
    #[inline]
    pub fn ik(&self, p: PointMm<F>) -> Result<MirrorAngles<F>, Error> {
        self.validate()?;
        p.check_finite()?;
        let y_rad = (p.y_mm / self.d_mm).atan() * F::HALF;
        let path_mm = (self.d_mm * self.d_mm + p.y_mm * p.y_mm).sqrt() + self.e_mm;
        let x_rad = (p.x_mm / path_mm).atan() * F::HALF;
        Ok(MirrorAngles { x_rad, y_rad })
    }

    /// Board point (mm) of the spot for mirror angles `a`.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`],
    /// [`Error::MissesBoard`] (a deflection of 90° or more).
    #[inline]
    pub fn fk(&self, a: MirrorAngles<F>) -> Result<PointMm<F>, Error> {
        self.validate()?;
        if !a.x_rad.is_finite() {
            return Err(Error::NonFinite { what: "x_rad" });
        }
        if !a.y_rad.is_finite() {
            return Err(Error::NonFinite { what: "y_rad" });
        }
        let (bx, by) = (a.x_rad * F::TWO, a.y_rad * F::TWO);
        if bx.abs() >= F::FRAC_PI_2 || by.abs() >= F::FRAC_PI_2 {
            return Err(Error::MissesBoard);
        }
        let y_mm = self.d_mm * by.tan();
        let x_mm = ((self.d_mm * self.d_mm + y_mm * y_mm).sqrt() + self.e_mm) * bx.tan();
        PointMm { x_mm, y_mm }
            .check_finite()
            .map_err(|_| Error::MissesBoard)
    }
}

/// A DAC output code with its clamp flag.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DacCode {
    /// Code written to the DAC, 0..=4095.
    pub code: u16,
    /// The angle was outside the DAC range and the code was clamped.
    pub clamped: bool,
}

/// Linear mapping of one axis: `code = round(offset_code + codes_per_rad·θ)`
/// with θ the mechanical angle in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DacAxis<F = f64> {
    /// DAC codes per mechanical radian (sign = direction), non-zero.
    pub codes_per_rad: F,
    /// Code for 0 rad (before rounding).
    pub offset_code: F,
}

impl<F: Real> Default for DacAxis<F> {
    /// SPEC default: ±12.5° mechanical spans the 12-bit range,
    /// `code = round(2047.5 + θ / 12.5° · 2047.5)`.
    fn default() -> Self {
        Self::span_of(DEFAULT_HALF_RANGE_DEG)
    }
}

impl<F: Real> DacAxis<F> {
    /// The axis whose full 12-bit range spans `±half_range_deg` mechanical
    /// (degrees, finite and > 0).
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`].
    pub fn spanning(half_range_deg: f64) -> Result<Self, Error> {
        if finite(half_range_deg, "half_range_deg")? <= 0.0 {
            return Err(Error::InvalidConfig {
                what: "DAC half range must be > 0",
            });
        }
        Ok(Self::span_of(half_range_deg))
    }

    fn span_of(half_range_deg: f64) -> Self {
        Self {
            codes_per_rad: F::from_f64(DAC_MID_CODE / half_range_deg.to_radians()),
            offset_code: F::from_f64(DAC_MID_CODE),
        }
    }

    /// DAC code for mechanical angle `theta_rad`, clamped to 0..=4095 (and
    /// flagged) when outside the range. Rounds half away from zero.
    ///
    /// The conversion stays in `F`: the code value is truncated to an
    /// integer (one `VCVT` in `f32`) and the remainder, exact in `F`,
    /// decides the rounding, so the `f32` path never widens to `f64`.
    ///
    /// Errors: [`Error::NonFinite`] (angle or mapping).
    #[inline]
    pub fn angle_to_code(&self, theta_rad: F) -> Result<DacCode, Error> {
        let value = self.offset_code + self.codes_per_rad * theta_rad;
        if !value.is_finite() {
            return Err(Error::NonFinite { what: "DAC code" });
        }
        Ok(round_to_code(value))
    }

    /// Mechanical angle (radians) of DAC code `code`.
    ///
    /// Errors: [`Error::DacCodeOutOfRange`] (> 4095),
    /// [`Error::InvalidConfig`] (zero or non-finite mapping).
    #[inline]
    pub fn code_to_angle(&self, code: u16) -> Result<F, Error> {
        if code > DAC_MAX_CODE {
            return Err(Error::DacCodeOutOfRange { code });
        }
        if !self.codes_per_rad.is_finite()
            || self.codes_per_rad == F::ZERO
            || !self.offset_code.is_finite()
        {
            return Err(Error::InvalidConfig {
                what: "DAC codes_per_rad must be finite and non-zero",
            });
        }
        Ok((F::from_f64(f64::from(code)) - self.offset_code) / self.codes_per_rad)
    }
}

/// A finite code value rounded half away from zero to a DAC code,
/// clamped (and flagged) outside 0..=4095, without leaving `F`: the value
/// is truncated to an integer (one `VCVT` in `f32`) and the remainder,
/// exact in `F`, decides the rounding.
#[inline]
pub(crate) fn round_to_code<F: Real>(value: F) -> DacCode {
    // round(value) < 0 ⇔ value ≤ −½; round(value) > 4095 ⇔ value ≥ 4095½.
    let top = F::from_u16(DAC_MAX_CODE) + F::HALF;
    if value <= -F::HALF {
        DacCode {
            code: 0,
            clamped: true,
        }
    } else if value >= top {
        DacCode {
            code: DAC_MAX_CODE,
            clamped: true,
        }
    } else {
        // value ∈ (−½, 4095½): −½ < value < 0 truncates to 0 and rounds to
        // 0; otherwise value − trunc(value) is exact.
        // Below 4096: the narrowing cast is exact.
        let whole = value.trunc_to_u32() as u16;
        let up = value - F::from_u16(whole) >= F::HALF;
        DacCode {
            code: whole + u16::from(up),
            clamped: false,
        }
    }
}

/// DAC codes of both axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DacCodes {
    /// X axis (DAC1 channel 1).
    pub x: DacCode,
    /// Y axis (DAC1 channel 2).
    pub y: DacCode,
}

impl DacCodes {
    /// Whether either axis was clamped.
    pub fn clamped(&self) -> bool {
        self.x.clamped || self.y.clamped
    }
}

/// A complete galvo: geometry and both DAC mappings. `Copy`; [`Default`]
/// holds the SPEC defaults. Use `Galvo<f32>` per sample, `Galvo<f64>` as
/// the reference; [`Galvo::cast`] converts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Galvo<F = f64> {
    /// Mirror geometry.
    pub geometry: GalvoGeometry<F>,
    /// X mirror DAC mapping.
    pub dac_x: DacAxis<F>,
    /// Y mirror DAC mapping.
    pub dac_y: DacAxis<F>,
}

impl<F: Real> Default for Galvo<F> {
    /// SPEC defaults: d = 400 mm, e = 10 mm, ±12.5° on both DAC axes.
    fn default() -> Self {
        Self {
            geometry: GalvoGeometry::default(),
            dac_x: DacAxis::default(),
            dac_y: DacAxis::default(),
        }
    }
}

impl<F: Real> Galvo<F> {
    /// Board point (mm) → mirror angles → DAC codes.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`].
    #[inline]
    pub fn board_to_codes(&self, p: PointMm<F>) -> Result<DacCodes, Error> {
        let a = self.geometry.ik(p)?;
        self.angles_to_codes(a)
    }

    /// Mirror angles → DAC codes.
    ///
    /// Errors: [`Error::NonFinite`].
    #[inline]
    pub fn angles_to_codes(&self, a: MirrorAngles<F>) -> Result<DacCodes, Error> {
        Ok(DacCodes {
            x: self.dac_x.angle_to_code(a.x_rad)?,
            y: self.dac_y.angle_to_code(a.y_rad)?,
        })
    }

    /// DAC codes → mirror angles.
    ///
    /// Errors: [`Error::DacCodeOutOfRange`], [`Error::InvalidConfig`].
    pub fn codes_to_angles(&self, x_code: u16, y_code: u16) -> Result<MirrorAngles<F>, Error> {
        Ok(MirrorAngles {
            x_rad: self.dac_x.code_to_angle(x_code)?,
            y_rad: self.dac_y.code_to_angle(y_code)?,
        })
    }

    /// DAC codes → board point (mm).
    ///
    /// Errors: [`Error::DacCodeOutOfRange`], [`Error::InvalidConfig`],
    /// [`Error::MissesBoard`].
    pub fn codes_to_board(&self, x_code: u16, y_code: u16) -> Result<PointMm<F>, Error> {
        self.geometry.fk(self.codes_to_angles(x_code, y_code)?)
    }

    /// The same galvo in another float type (e.g. `f64` settings → `f32`
    /// per-sample copy).
    pub fn cast<G: Real>(&self) -> Galvo<G> {
        let c = |v: F| G::from_f64(v.to_f64());
        Galvo {
            geometry: GalvoGeometry {
                d_mm: c(self.geometry.d_mm),
                e_mm: c(self.geometry.e_mm),
            },
            dac_x: DacAxis {
                codes_per_rad: c(self.dac_x.codes_per_rad),
                offset_code: c(self.dac_x.offset_code),
            },
            dac_y: DacAxis {
                codes_per_rad: c(self.dac_y.codes_per_rad),
                offset_code: c(self.dac_y.offset_code),
            },
        }
    }
}
