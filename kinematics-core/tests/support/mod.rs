//! Test data shared by this crate's tests and the system tests
//! (`tests/tests/calibration_sse.rs` includes this file by path).

use kinematics_core::MeasuredPoint;

/// The 11 × 11 noisy grid of `kinematics-core/tests/data/quadratic_noise.csv`
/// (mm).
pub fn noisy_grid() -> Vec<MeasuredPoint> {
    include_str!("../data/quadratic_noise.csv")
        .lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|f| f.trim().parse().unwrap()).collect();
            MeasuredPoint {
                x_mm: v[0],
                y_mm: v[1],
                dx_mm: v[2],
                dy_mm: v[3],
            }
        })
        .collect()
}
