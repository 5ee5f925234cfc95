//! Host simulator of the laser pointing controller: runs the firmware's task
//! bodies (from `laser-app`) on embassy's executor in virtual time, against
//! simulated FashionStar servos and galvos, and records where the laser went.

pub mod bench;
pub mod board;
pub mod clock;
pub mod controls;
pub mod dac;
pub mod drawing;
pub mod executor;
pub mod flash;
pub mod laser;
pub mod logger;
#[cfg(unix)]
pub mod on_pty;
pub mod panel;
pub mod pelco_port;
pub mod physics;
#[cfg(unix)]
pub mod pty;
pub mod recorder;
pub mod safety;
pub mod script;
pub mod servo_model;
pub mod servo_port;
pub mod settings_flash;
pub mod spot;
pub mod spot_feed;
pub mod stepper;
pub mod usb_host;
pub mod world;

/// The galvo spot of a run: its path and where the laser was on (cm).
pub fn galvo_trace(dac: &dac::DacRecording, galvo: &physics::PhysicalGalvo) -> drawing::GalvoTrace {
    let mut trace = drawing::GalvoTrace::default();
    for (_, _, _, sample) in dac.runs() {
        let Some(spot) = galvo.spot_cm(sample.x_code, sample.y_code) else {
            continue;
        };
        if trace.path.last() != Some(&spot) {
            trace.path.push(spot);
        }
        // Lit spots closer than 0.2 mm to the last one drawn add nothing.
        let near = |p: &(f64, f64)| (p.0 - spot.0).hypot(p.1 - spot.1) < 0.02;
        if sample.laser && !trace.lit.last().is_some_and(near) {
            trace.lit.push(spot);
        }
    }
    // A galvo that never moved is not worth drawing.
    if trace.path.len() < 2 && trace.lit.is_empty() {
        trace.path.clear();
    }
    trace
}

/// Draws a run: board, grid (default geometry), both spots and dwells.
pub fn render(report: &world::SimReport, title: &str) -> anyhow::Result<String> {
    let settings = laser_app::settings::Settings::default();
    drawing::render_svg(
        &report.recording,
        &galvo_trace(&report.dac, &physics::PhysicalGalvo::default()),
        drawing::GridView {
            pitch_cm: settings.grid_pitch_cm,
            half_cols: i32::from(settings.grid_cols / 2),
            half_rows: i32::from(settings.grid_rows / 2),
        },
        title,
    )
}
