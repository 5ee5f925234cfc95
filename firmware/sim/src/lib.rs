//! Host simulator of the laser pointing controller: runs the firmware's task
//! bodies (from `laser-app`) on embassy's executor in virtual time, against
//! simulated FashionStar servos and galvos, and records where the laser went.

pub mod clock;
pub mod dac;
pub mod drawing;
pub mod executor;
pub mod logger;
pub mod physics;
pub mod recorder;
pub mod script;
pub mod servo_model;
pub mod servo_port;
pub mod usb_host;
pub mod world;

/// Draws a run: board, grid (default geometry), spot path and dwells.
pub fn render(report: &world::SimReport, title: &str) -> anyhow::Result<String> {
    let settings = laser_app::settings::Settings::default();
    drawing::render_svg(
        &report.recording,
        drawing::GridView {
            pitch_cm: settings.grid_pitch_cm,
            half_cols: i32::from(settings.grid_cols / 2),
            half_rows: i32::from(settings.grid_rows / 2),
        },
        title,
    )
}
