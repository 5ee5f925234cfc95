//! From board points to servo angles: the aiming chain board point →
//! error-model compensation → gimbal IK (exact or seed) → servo mapping →
//! FashionStar wire value, and the other geometry a run looks up per point
//! (grid, galvo DAC range, path step). All geometry is `kinematics-core`;
//! [`Aimer`] holds it, built once per change of the settings
//! ([`Settings::aimer`](crate::settings::Settings::aimer)).

use kinematics_core as kc;
use kinematics_core::{ErrorModel, Galvo, Gimbal, Grid, GridIndex};

use super::figure::Pattern;
use super::point::PointCm;

/// One point the sequencer visits.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Target {
    /// Board point, cm.
    pub point: PointCm,
    /// Grid index `(xi, yi)` when the point is a grid point.
    pub grid: Option<(i8, i8)>,
}

/// Where the servos go for a target.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Aim {
    /// Yaw joint angle, deg.
    pub yaw_deg: f64,
    /// Pitch joint angle, deg.
    pub pitch_deg: f64,
    /// Yaw servo angle on the wire, 0.1 deg.
    pub yaw_wire: i16,
    /// Pitch servo angle on the wire, 0.1 deg.
    pub pitch_wire: i16,
}

/// The calibrated geometry of one set of settings and one gimbal model,
/// built once and used for many points (a run or a check of many points
/// does not rebuild the gimbal, grid, error model and galvo mapping for
/// each of them).
#[derive(Debug, Clone, Copy)]
pub struct Aimer {
    error_model: ErrorModel,
    gimbal: Gimbal,
    grid: Grid,
    galvo: Galvo<f64>,
    path_step_cm: f64,
}

impl Aimer {
    /// The chain of `gimbal` behind `error_model`, points of `grid`, the
    /// galvo mapping `galvo` (its DAC range), and paths interpolated in
    /// steps of `path_step_cm` (cm).
    pub fn new(
        gimbal: Gimbal,
        error_model: ErrorModel,
        grid: Grid,
        galvo: Galvo<f64>,
        path_step_cm: f64,
    ) -> Self {
        Self {
            error_model,
            gimbal,
            grid,
            galvo,
            path_step_cm,
        }
    }

    /// Servo angles that put the spot on board point `point` (cm): the
    /// error model pre-compensates the point, the gimbal IK gives the joint
    /// angles, the servo mapping the wire values (limits checked).
    ///
    /// Errors: unreachable or non-finite targets, servo limits, a
    /// diverging error model — never NaN angles.
    pub fn aim(&self, point: PointCm) -> Result<Aim, kc::Error> {
        let corrected = self.error_model.compensate_board(point.board())?;
        let joints = self.gimbal.ik(corrected)?;
        let wire = self.gimbal.to_wire(joints)?;
        Ok(Aim {
            yaw_deg: joints.yaw_deg,
            pitch_deg: joints.pitch_deg,
            yaw_wire: wire.yaw,
            pitch_wire: wire.pitch,
        })
    }

    /// The grid point `(xi, yi)`.
    ///
    /// Errors: index outside the configured grid.
    pub fn grid_point(&self, xi: i8, yi: i8) -> Result<Target, kc::Error> {
        let point = self.grid.point(GridIndex { xi, yi })?;
        Ok(Target {
            point: PointCm::from_board(point),
            grid: Some((xi, yi)),
        })
    }

    /// Point `index` (from 0) of one pass of grid pattern `pattern`, in
    /// O(1); `None` past the end of the pass or for a path (its points
    /// come from a [`PathCursor`](super::path::PathCursor)).
    pub fn grid_target(&self, pattern: &Pattern, index: usize) -> Option<Target> {
        let idx = pattern.grid()?.indices(&self.grid).nth(index)?;
        let point = self.grid.point(idx).ok()?;
        Some(Target {
            point: PointCm::from_board(point),
            grid: Some((idx.xi, idx.yi)),
        })
    }

    /// Points in one pass of grid pattern `pattern` (0 for a path).
    pub fn grid_points(&self, pattern: &Pattern) -> usize {
        pattern
            .grid()
            .map_or(0, |grid| grid.indices(&self.grid).len())
    }

    /// Whether the galvo can reach board point `point` (cm) within its DAC
    /// range.
    pub fn galvo_in_range(&self, point: PointCm) -> bool {
        self.galvo
            .board_to_codes(point.mm())
            .is_ok_and(|codes| !codes.clamped())
    }

    /// Step of path interpolation, cm.
    pub fn path_step_cm(&self) -> f64 {
        self.path_step_cm
    }

    /// The gimbal.
    pub fn gimbal(&self) -> &Gimbal {
        &self.gimbal
    }

    /// The error model the points are compensated with.
    pub fn error_model(&self) -> &ErrorModel {
        &self.error_model
    }
}
