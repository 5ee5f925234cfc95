//! The gimbal's joint angles, shared by both models and the calibrated
//! chain.

/// Gimbal joint angles, degrees.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JointAngles {
    /// Yaw α, degrees.
    pub yaw_deg: f64,
    /// Pitch β, degrees.
    pub pitch_deg: f64,
}
