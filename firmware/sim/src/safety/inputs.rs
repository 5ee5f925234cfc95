//! What the checker reads: a finished run's records, the galvo output as
//! stretches of equal samples.

use crate::controls::ControlsRecord;
use crate::dac::DacRecording;
use crate::executor::TaskSteps;
use crate::physics::PhysicalGalvo;
use crate::recorder::{EventRecord, ServoSample, SpotSample};
use crate::usb_host::Transcript;
use crate::world::SimReport;

/// A stretch of equal galvo DAC samples, one half buffer at most, as the
/// checker sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GalvoStretch {
    /// Output time of its first sample, ns.
    pub start_ns: u64,
    /// Sample period, ns.
    pub period_ns: u64,
    /// Samples.
    pub count: u64,
    /// X mirror DAC code.
    pub x_code: u16,
    /// Y mirror DAC code.
    pub y_code: u16,
    /// Effective laser state: what the beam does.
    pub laser: bool,
    /// When the galvo loop computed these samples, ns.
    pub computed_ns: u64,
}

impl GalvoStretch {
    /// Output time of its last sample, ns.
    pub fn last_ns(&self) -> u64 {
        self.start_ns + self.count.saturating_sub(1) * self.period_ns
    }
}

/// The galvo output as stretches of equal samples split at half-buffer
/// boundaries, in output order. This is the one place the checker reads
/// the galvo laser: the recorded laser column is the effective one (when
/// the simulator records a master laser gate, AND it in here).
pub fn galvo_stretches(dac: &DacRecording) -> Vec<GalvoStretch> {
    let halves = &dac.halves;
    let mut out = Vec::new();
    let mut half = 0usize;
    let mut k = 0usize;
    for (start_ns, period_ns, count, sample) in dac.runs() {
        let mut first = k;
        let end = k + count as usize;
        while first < end {
            while half + 1 < halves.len() && halves[half + 1].first_sample <= first {
                half += 1;
            }
            let half_end = halves.get(half + 1).map_or(usize::MAX, |h| h.first_sample);
            let last = end.min(half_end);
            out.push(GalvoStretch {
                start_ns: start_ns + (first - k) as u64 * period_ns,
                period_ns,
                count: (last - first) as u64,
                x_code: sample.x_code,
                y_code: sample.y_code,
                laser: sample.laser,
                computed_ns: halves.get(half).map_or(0, |h| h.computed_ns),
            });
            first = last;
        }
        k = end;
    }
    out
}

/// What the checker reads: borrowed from a [`SimReport`].
#[derive(Debug, Clone)]
pub struct SafetyInputs<'a> {
    /// Gimbal laser switching: (t µs, on), in order.
    pub gimbal_laser: &'a [(u64, bool)],
    /// Galvo output (effective laser).
    pub galvo: Vec<GalvoStretch>,
    /// When the galvo loop learned of each underrun, ns.
    pub underruns_ns: &'a [u64],
    /// Sequencer events, in processing order.
    pub events: &'a [EventRecord],
    /// Servo angles and targets.
    pub servos: &'a [ServoSample],
    /// The gimbal's or stepper's spot on the board.
    pub spot: &'a [SpotSample],
    /// The terminal transcript.
    pub transcript: &'a Transcript,
    /// Step accounting of every task.
    pub task_steps: &'a [TaskSteps],
    /// The true galvo (DAC codes → board).
    pub galvo_physics: PhysicalGalvo,
    /// Simulated time at the end of the run, µs.
    pub end_us: u64,
    /// The laser controls' inputs and indicator (`None`: the board has
    /// none).
    pub controls: Option<&'a ControlsRecord>,
}

impl<'a> SafetyInputs<'a> {
    /// The inputs of a finished run.
    pub fn from_report(report: &'a SimReport) -> Self {
        Self {
            gimbal_laser: &report.recording.laser_events,
            galvo: galvo_stretches(&report.dac),
            underruns_ns: &report.dac.underrun_detected_ns,
            events: &report.recording.events,
            servos: &report.recording.servos,
            spot: &report.recording.spot,
            transcript: &report.transcript,
            task_steps: &report.task_steps,
            galvo_physics: PhysicalGalvo::default(),
            end_us: report.end_time_us,
            controls: report.laser_controls.as_ref(),
        }
    }
}
