//! The grbl side of the sequencer: G-code and `$` lines from the console
//! (through [`crate::grbl`]'s parser into the motion queue of
//! [`crate::sequencer::gcode::queue`]), grbl's realtime commands, and every reply a
//! sender expects (`ok` once a line's motion is queued, `error:N`,
//! `ALARM:N`, status reports).

use crate::grbl::report::Overrides;
use crate::grbl::settings_map;
use crate::grbl::{ParserState, SpindleMode};
use crate::sequencer::gcode::queue::Motion;
use crate::settings::{LaserMode, Settings};

/// RAM the G-code path adds, bytes (host layout): the sequencer's grbl
/// session with its motion queue, the drivers' G-code state, the
/// realtime command queue and the console's RX buffer.
pub const GCODE_RAM_BYTES: usize = core::mem::size_of::<GcodeSession>()
    + core::mem::size_of::<crate::sequencer::drivers::DriverJobs>()
    + core::mem::size_of::<
        embassy_sync::channel::Channel<
            embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex,
            crate::command::RealtimeRequest,
            { crate::command::REALTIME_QUEUE_DEPTH },
        >,
    >()
    + crate::grbl::RX_BUFFER_BYTES;

/// grbl's RX buffer as `$I` advertises it, bytes.
pub(in crate::sequencer) const RX_BUFFER_BYTES: u16 = crate::grbl::RX_BUFFER_BYTES as u16;

/// Overrides at power-up and after a reset: 100 %.
const NO_OVERRIDES: Overrides = Overrides {
    feed: 100,
    rapid: 100,
    spindle: 100,
};

/// Whether G-code runs, is only checked, or is locked by an alarm.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::sequencer) enum GrblMode {
    /// Lines are queued and run.
    Normal,
    /// `$C`: lines are parsed and answered, nothing moves.
    Check,
    /// Locked until `$X`, `$H` or a reset.
    Alarm,
}

/// The grbl session's state.
#[derive(Debug, Clone)]
pub(in crate::sequencer) struct GcodeSession {
    /// Modal state of the lines accepted so far.
    pub(in crate::sequencer) parser: ParserState,
    pub(in crate::sequencer) mode: GrblMode,
    /// grbl-only settings (`$10`, `$11`, `$12`, `$30`–`$32`).
    pub(in crate::sequencer) values: GrblValues,
    /// Feed / rapid / laser power overrides, %.
    pub(in crate::sequencer) overrides: Overrides,
    /// The motion queue and what runs.
    pub(in crate::sequencer) motion: Motion,
    /// Status reports sent (grbl adds `WCO:` / `Ov:` every few).
    pub(in crate::sequencer) reports: u32,
    /// Actual over programmed speed of the gimbal step in flight, 0..=1
    /// (M4 scales the power by it; [`GcodeSession::gimbal_power`]).
    pub(in crate::sequencer) step_speed_ratio: f32,
    /// A `$H` on the stepper waits for homing to end for its reply.
    pub(in crate::sequencer) homing: bool,
    /// The junction deviation the stepper plans with when G-code set it
    /// (`$11` in joint degrees; `None`: the product's, from its settings).
    pub(in crate::sequencer) stepper_junction_deg: Option<f64>,
}

impl GcodeSession {
    /// Power-up state.
    pub(in crate::sequencer) fn new() -> Self {
        Self {
            parser: ParserState::new(),
            mode: GrblMode::Normal,
            values: GrblValues::default(),
            overrides: NO_OVERRIDES,
            motion: Motion::new(),
            reports: 0,
            step_speed_ratio: 0.0,
            homing: false,
            stepper_junction_deg: None,
        }
    }

    /// Whether laser setting (`mode`, `power`) lights a feed move: a
    /// power above `$31`'s and the laser mode (`laser auto`) allowing it.
    pub(in crate::sequencer) fn lit(
        &self,
        mode: SpindleMode,
        power: f64,
        settings: &Settings,
    ) -> bool {
        let v = &self.values;
        let fraction = crate::grbl::Laser { mode, power }.fraction(v.s_min, v.s_max);
        fraction > 0.0 && settings.laser_mode == LaserMode::Auto
    }
}

/// grbl-only settings the session keeps (RAM; defaults at boot and after
/// `$RST=$`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::sequencer) struct GrblValues {
    /// `$10`: bit 0 MPos (else WPos), bit 1 `Bf:`.
    pub(in crate::sequencer) report_mask: u8,
    /// `$12`: arc chord tolerance, mm.
    pub(in crate::sequencer) arc_tolerance_mm: f64,
    /// `$30`: S for full laser power.
    pub(in crate::sequencer) s_max: f64,
    /// `$31`: S for the lowest power.
    pub(in crate::sequencer) s_min: f64,
    /// `$32`: laser mode (G0 dark, M4 speed-scaled).
    pub(in crate::sequencer) laser_mode: bool,
}

fn default_of(number: u16) -> f64 {
    settings_map::find(number).map_or(0.0, |s| s.default)
}

impl Default for GrblValues {
    fn default() -> Self {
        Self {
            report_mask: default_of(10) as u8,
            arc_tolerance_mm: default_of(12),
            s_max: default_of(30),
            s_min: default_of(31),
            laser_mode: default_of(32) != 0.0,
        }
    }
}

/// The product parameter a grbl setting reads and writes, with the factor
/// grbl value = parameter × factor.
fn product_param(number: u16) -> Option<(&'static str, f64)> {
    match number {
        11 => Some(("gcode.junction_mm", 1.0)),
        110 | 111 => Some(("galvo.mark_speed_mm_s", 60.0)),
        120 | 121 => Some(("galvo.mark_accel_mm_s2", 1.0)),
        _ => None,
    }
}

pub(in crate::sequencer) mod context;
pub(in crate::sequencer) mod drive;
pub(in crate::sequencer) mod lines;
pub(in crate::sequencer) mod motion;
pub(in crate::sequencer) mod power;
pub(in crate::sequencer) mod proven;
pub(in crate::sequencer) mod queue;
pub(in crate::sequencer) mod reach;
pub(in crate::sequencer) mod report;
pub(in crate::sequencer) mod session;
pub(in crate::sequencer) mod settings;
pub(in crate::sequencer) mod step;
pub(in crate::sequencer) mod stepper;

#[cfg(test)]
pub(in crate::sequencer) mod tests;
