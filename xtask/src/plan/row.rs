//! One row of a simulated trajectory, as written to CSV and plotted.

/// One row of the trajectory: the state at `t = k·Ts` and the voltage held
/// over `[k·Ts, (k+1)·Ts)` (0 on the last row).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Row {
    pub k: usize,
    pub t_s: f64,
    pub theta_rad: f64,
    pub omega_rad_s: f64,
    pub current_a: f64,
    pub u_v: f64,
    /// Flexible model: (φ, ω_φ).
    pub load: Option<(f64, f64)>,
}
