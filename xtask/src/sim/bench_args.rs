//! `cargo xtask sim`'s options for how the simulated bench is built and
//! set (`laser_sim::bench::BenchBuild`): what a user's bench can be set to
//! and what a build gets wrong, so a run reproduces it from the command
//! line.

use laser_sim::bench::BenchBuild;

/// The simulated bench's build and switch settings.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct BenchArgs {
    /// The simulated stepper drivers' microstep switches (1, 2, 4, … 256;
    /// default 32). The firmware is not told: set `stepper.microsteps` to
    /// match, as on a real bench.
    #[arg(long, value_name = "N")]
    stepper_microsteps: Option<u32>,
    /// The board's real roll about the beam axis, degrees (build error).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    board_roll_deg: Option<f64>,
    /// Where the yaw/pan servo's zero really is, degrees (build error).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    yaw_zero_deg: Option<f64>,
    /// Where the pitch/tilt servo's zero really is, degrees (build error).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pitch_zero_deg: Option<f64>,
    /// The board's real distance from the gimbal, cm (the firmware's
    /// `oq_cm` is what it assumes).
    #[arg(long, value_name = "CM")]
    board_distance_cm: Option<f64>,
}

impl BenchArgs {
    /// The bench these options describe (unset: the SPEC's).
    pub fn build(&self) -> BenchBuild {
        let spec = BenchBuild::default();
        BenchBuild {
            stepper_microsteps: self.stepper_microsteps.unwrap_or(spec.stepper_microsteps),
            board_roll_deg: self.board_roll_deg.unwrap_or(spec.board_roll_deg),
            yaw_zero_deg: self.yaw_zero_deg.unwrap_or(spec.yaw_zero_deg),
            pitch_zero_deg: self.pitch_zero_deg.unwrap_or(spec.pitch_zero_deg),
            board_distance_cm: self.board_distance_cm.or(spec.board_distance_cm),
        }
    }
}
