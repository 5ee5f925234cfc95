//! Servo-gimbal kinematics: the exact coupled model (default, SPEC §4.3)
//! and the seed's model (SPEC §4.2), forward and inverse, plus [`Gimbal`],
//! the whole calibrated chain board point ↔ joint angles ↔ servo wire
//! values.
//!
//! Joint angles are the seed's: yaw α about global z (positive turns the
//! beam toward global +y, i.e. board −x) and pitch β (positive tilts the
//! beam down), both in degrees; α = β = 0 points the beam along +x from
//! `L = (0, 0, OL)`.

pub mod exact;
mod joints;
pub mod seed;

pub use joints::JointAngles;

use crate::error::{Error, Joint};
use crate::frames::{BoardFrame, BoardPoint, GlobalPoint};
use crate::numeric::finite;
use crate::servo::{ServoAxis, WireAngles};

/// SPEC default laser axis offset OL, cm.
pub const DEFAULT_OL_CM: f64 = 5.4;

/// Which gimbal model to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GimbalModel {
    /// The exact coupled model (SPEC §4.3).
    #[default]
    Exact,
    /// The seed's model (SPEC §4.2), for comparison.
    Seed,
}

impl GimbalModel {
    /// `"exact"` or `"seed"`.
    pub fn name(self) -> &'static str {
        match self {
            GimbalModel::Exact => "exact",
            GimbalModel::Seed => "seed",
        }
    }

    /// Parses `"exact"` / `"seed"` (ASCII case-insensitive).
    pub fn from_name(name: &str) -> Option<Self> {
        [GimbalModel::Exact, GimbalModel::Seed]
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(name))
    }

    /// This model's IK for a global point (cm); `ol_cm` = OL (cm). No servo
    /// limits. Errors: see [`exact::ik`] / [`seed::ik`].
    pub fn ik(self, ol_cm: f64, p: GlobalPoint) -> Result<JointAngles, Error> {
        match self {
            GimbalModel::Exact => exact::ik(ol_cm, p),
            GimbalModel::Seed => seed::ik(ol_cm, p),
        }
    }

    /// This model's FK onto the plane `x_g = plane_x_cm` (cm). Errors: see
    /// [`exact::fk`] / [`seed::fk`].
    pub fn fk(self, ol_cm: f64, plane_x_cm: f64, j: JointAngles) -> Result<GlobalPoint, Error> {
        match self {
            GimbalModel::Exact => exact::fk(ol_cm, plane_x_cm, j),
            GimbalModel::Seed => seed::fk(ol_cm, plane_x_cm, j),
        }
    }
}

/// The calibrated servo gimbal: model, geometry, board placement and the
/// two servo mappings. `Copy`; [`Default`] holds the SPEC defaults.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Gimbal {
    /// Kinematic model (default exact).
    pub model: GimbalModel,
    /// Geometry and servo calibration.
    pub geometry: GimbalGeometry,
}

/// Geometry and calibration of the gimbal (everything but the model choice).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GimbalGeometry {
    /// Laser axis offset OL from the rotation centre, cm (≥ 0).
    pub ol_cm: f64,
    /// Where the board is (OQ, offsets, pose).
    pub frame: BoardFrame,
    /// Yaw servo mapping.
    pub yaw: ServoAxis,
    /// Pitch servo mapping.
    pub pitch: ServoAxis,
}

impl Default for GimbalGeometry {
    /// SPEC defaults: OL = 5.4 cm, OQ = 25 cm, no offsets or pose error,
    /// servos direction +1, scale 1, zero 0, limits ±135°.
    fn default() -> Self {
        Self {
            ol_cm: DEFAULT_OL_CM,
            frame: BoardFrame::default(),
            yaw: ServoAxis::default(),
            pitch: ServoAxis::default(),
        }
    }
}

impl Gimbal {
    /// The SPEC default gimbal with the given model.
    pub fn with_model(model: GimbalModel) -> Self {
        Self {
            model,
            geometry: GimbalGeometry::default(),
        }
    }

    /// Checks OL, the frame and both servo calibrations.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`],
    /// [`Error::BehindGimbal`].
    pub fn validate(&self) -> Result<(), Error> {
        exact::check_ol(self.geometry.ol_cm)?;
        self.geometry.frame.validate()?;
        self.geometry.yaw.validate()?;
        self.geometry.pitch.validate()
    }

    /// Joint angles (degrees) that put the spot on the board point `target`
    /// (cm; the frame's offsets are added), within both servos' limits.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`],
    /// [`Error::BehindGimbal`], [`Error::InsideOffsetCircle`],
    /// [`Error::JointLimit`].
    pub fn ik(&self, target: BoardPoint) -> Result<JointAngles, Error> {
        self.validate()?;
        let g = self.geometry.frame.board_to_global(target)?;
        let j = self.model.ik(self.geometry.ol_cm, g)?;
        self.check_limits(j)?;
        Ok(j)
    }

    /// Board point (cm, offsets removed) the spot lands on for joint angles
    /// `j` (degrees). No limit check.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`],
    /// [`Error::BehindGimbal`], [`Error::MissesBoard`].
    pub fn fk(&self, j: JointAngles) -> Result<BoardPoint, Error> {
        self.validate()?;
        let frame = &self.geometry.frame;
        let g = self.model.fk(self.geometry.ol_cm, frame.plane_x_cm()?, j)?;
        frame.global_to_board(g)
    }

    /// `Ok` if both joint angles map inside their servo limits.
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`],
    /// [`Error::JointLimit`].
    pub fn check_limits(&self, j: JointAngles) -> Result<(), Error> {
        self.geometry
            .yaw
            .joint_to_servo_deg(Joint::Yaw, j.yaw_deg)?;
        self.geometry
            .pitch
            .joint_to_servo_deg(Joint::Pitch, j.pitch_deg)?;
        Ok(())
    }

    /// Joint angles (degrees) → FashionStar wire values (0.1°).
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`],
    /// [`Error::JointLimit`].
    pub fn to_wire(&self, j: JointAngles) -> Result<WireAngles, Error> {
        Ok(WireAngles {
            yaw: self.geometry.yaw.joint_to_wire(Joint::Yaw, j.yaw_deg)?,
            pitch: self
                .geometry
                .pitch
                .joint_to_wire(Joint::Pitch, j.pitch_deg)?,
        })
    }

    /// FashionStar wire values (0.1°) → joint angles (degrees).
    ///
    /// Errors: [`Error::NonFinite`], [`Error::InvalidConfig`].
    pub fn from_wire(&self, w: WireAngles) -> Result<JointAngles, Error> {
        Ok(JointAngles {
            yaw_deg: self.geometry.yaw.wire_to_joint(w.yaw)?,
            pitch_deg: self.geometry.pitch.wire_to_joint(w.pitch)?,
        })
    }

    /// Board point (cm) → wire values: [`ik`](Self::ik) then
    /// [`to_wire`](Self::to_wire).
    ///
    /// Errors: as [`ik`](Self::ik).
    pub fn ik_wire(&self, target: BoardPoint) -> Result<WireAngles, Error> {
        self.to_wire(self.ik(target)?)
    }

    /// Wire values → board point (cm): [`from_wire`](Self::from_wire) then
    /// [`fk`](Self::fk).
    ///
    /// Errors: as [`fk`](Self::fk).
    pub fn fk_wire(&self, w: WireAngles) -> Result<BoardPoint, Error> {
        self.fk(self.from_wire(w)?)
    }

    /// Distance (cm) between where this gimbal's IK aims and where the spot
    /// really lands according to the exact model: the pointing error of
    /// the seed model, ~0 for the exact one.
    ///
    /// Errors: as [`ik`](Self::ik) and [`fk`](Self::fk).
    pub fn pointing_error_cm(&self, target: BoardPoint) -> Result<f64, Error> {
        let j = self.ik(target)?;
        let exact = Gimbal {
            model: GimbalModel::Exact,
            ..*self
        };
        let spot = exact.fk(j)?;
        Ok(finite(
            crate::numeric::hypot(spot.x_cm - target.x_cm, spot.y_cm - target.y_cm),
            "pointing error",
        )?)
    }
}

#[cfg(test)]
mod tests;
