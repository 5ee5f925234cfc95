//! What a simulation is asked to do ([`SimOptions`]) and what it
//! produced ([`SimReport`]).

use crate::controls::ControlsRecord;
use crate::dac::DacRecording;
use crate::executor::{self, RunEnd};
use crate::flash::{FlashStats, PowerCut};
use crate::panel::PanelRecord;
use crate::physics::PhysicalGimbal;
use crate::recorder::Recording;
use crate::script::Step;
use crate::servo_port::BusFaults;
use crate::stepper::{DriverTiming, LimitSwitch, MotorLimits, PanTiltDrivers, StepperGeometry};
use crate::usb_host::Transcript;

/// How to run a simulation.
#[derive(Debug, Clone)]
pub struct SimOptions {
    /// The command lines to type (and waits).
    pub script: Vec<Step>,
    /// Type what the user types on stdin instead of `script` (real time,
    /// until end of input).
    pub interactive: bool,
    /// Pace with the wall clock instead of jumping over idle time.
    pub realtime: bool,
    /// Keep running after the script until the sequencer is idle.
    pub until_idle: bool,
    /// Injected servo-bus faults.
    pub faults: BusFaults,
    /// Servos move this many times slower than commanded (1 = nominal).
    pub slow_factor: f64,
    /// The ids the servos on the bus have at power-up, in slot order (the
    /// first drives yaw, the second pitch; `@unplug-servo <slot>` counts
    /// from 1). `None`: the physical gimbal's `yaw_id` and `pitch_id`.
    /// `Some(vec![0, 0])` is two servos as they ship.
    pub servo_ids: Option<Vec<u8>>,
    /// Hard limit on simulated time, ms.
    pub max_time_ms: u64,
    /// Print the terminal transcript on stdout as it happens.
    pub echo: bool,
    /// Period of the spot sampler, µs.
    pub sample_period_us: u64,
    /// Saved settings record to boot with (saved through the store into
    /// erased flash before the boot).
    pub saved_settings: Option<Vec<u8>>,
    /// The settings sectors to boot from, as an earlier run left them
    /// ([`SimReport::settings_flash`]); overrides `saved_settings`.
    pub settings_flash: Option<Vec<u8>>,
    /// Cut the power of the settings flash at this program/erase step
    /// (counted from boot); the flash then refuses every access.
    pub settings_flash_cut: Option<PowerCut>,
    /// The true gimbal: bus ids, geometry, servo mounting and board pose
    /// (set a pose or zero error to model a real, imperfect build).
    pub physical: PhysicalGimbal,
    /// Galvo loop compute time charged per DAC sample, ns (0: the loop
    /// is instant; above the sample period it underruns).
    pub galvo_cost_ns_per_sample: u64,
    /// Charge the galvo loop's work at the M4's cost (default; `false`:
    /// the loop's work is free, to compare what the jump planners draw,
    /// `planner seed` included).
    pub galvo_m4_cost: bool,
    /// The board has a galvo DAC (`false`: a board like the target's,
    /// which has none yet, so no galvo loop runs).
    pub galvo_dac: bool,
    /// The board has the stepper pan/tilt's outputs.
    pub stepper: bool,
    /// The stepper drivers' input timing.
    pub stepper_timing: DriverTiming,
    /// What the stepper motors can do (the pull-out model).
    pub stepper_motor: MotorLimits,
    /// The true stepper pan/tilt geometry (the spot comes from its
    /// counted steps).
    pub stepper_geometry: StepperGeometry,
    /// Limit switches on the stepper axes `[pan, tilt]` (none: inputs
    /// read open).
    pub stepper_switches: [Option<LimitSwitch>; 2],
    /// The board has the laser controls (interlock, key switch, emission
    /// indicator; bench wiring: closed and on). Also fitted when the
    /// script has `@interlock` or `@key` steps.
    pub laser_controls: bool,
    /// Serve the console on a pseudo-terminal instead of the script
    /// (real time; the run ends when its stop flag is set).
    #[cfg(unix)]
    pub pty: Option<crate::pty::PtyOptions>,
    /// The board's PELCO port on a pseudo-terminal (real time: set
    /// `realtime` too); none without.
    #[cfg(unix)]
    pub pelco_pty: Option<crate::pelco_port::PelcoPtyOptions>,
    /// Publish where the spot really is to this file
    /// ([`crate::spot_feed`]: what a virtual camera outside the
    /// simulator renders).
    pub spot_feed: Option<std::path::PathBuf>,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            script: Vec::new(),
            interactive: false,
            realtime: false,
            until_idle: false,
            faults: BusFaults::default(),
            slow_factor: 1.0,
            servo_ids: None,
            max_time_ms: 600_000,
            echo: false,
            sample_period_us: 2_000,
            saved_settings: None,
            settings_flash: None,
            settings_flash_cut: None,
            physical: PhysicalGimbal::default(),
            galvo_cost_ns_per_sample: 0,
            galvo_m4_cost: true,
            galvo_dac: true,
            stepper: true,
            stepper_timing: DriverTiming::default(),
            stepper_motor: MotorLimits::default(),
            stepper_geometry: StepperGeometry::default(),
            stepper_switches: [None; 2],
            laser_controls: false,
            #[cfg(unix)]
            pty: None,
            #[cfg(unix)]
            pelco_pty: None,
            spot_feed: None,
        }
    }
}

/// What a simulation produced.
#[derive(Debug, Clone)]
pub struct SimReport {
    /// Everything the terminal sent and received.
    pub transcript: Transcript,
    /// Spot, dwells, laser switching, servo-bus frames.
    pub recording: Recording,
    /// Why the run ended.
    pub end: RunEnd,
    /// Simulated time at the end, µs.
    pub end_time_us: u64,
    /// The sequencer was idle (or holding a goto) at the end.
    pub idle_at_end: bool,
    /// The settings record a reboot would load from the flash as the run
    /// left it, if any.
    pub saved_settings: Option<Vec<u8>>,
    /// The settings sectors at the end (boot the next run from them).
    pub settings_flash: Vec<u8>,
    /// What the settings flash did during the run.
    pub settings_flash_stats: FlashStats,
    /// Every galvo DAC sample.
    pub dac: DacRecording,
    /// Galvo underruns.
    pub galvo_underruns: u32,
    /// CPU-time accounting of every task's steps (polls).
    pub task_steps: Vec<executor::TaskSteps>,
    /// What the board's LEDs, stop button and watchdog did.
    pub panel: PanelRecord,
    /// The stepper drivers: counted steps, pulse timing, stalls, edges.
    pub stepper: PanTiltDrivers,
    /// What the laser controls did, on a board with them.
    pub laser_controls: Option<ControlsRecord>,
    /// What crossed the PELCO port (nothing on a run without one).
    pub pelco: crate::pelco_port::PelcoTraffic,
}

impl SimReport {
    /// Whether `--until-idle` should exit 0: script done, idle, and no
    /// `error:` reply unless errors are allowed.
    pub fn succeeded(&self, allow_errors: bool) -> bool {
        self.end != RunEnd::Livelock
            && self.transcript.script_done
            && self.idle_at_end
            && (allow_errors || self.transcript.error_replies == 0)
    }
}
