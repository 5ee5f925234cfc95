//! The job queue: requests checked and queued, parameters applied at
//! job boundaries, stop and underrun.

use kinematics_core::PointMm;

use kinematics_core::SampleMap;

use super::build::samples_for;
use super::state::Motion;
use super::{Active, GalvoConfig, GalvoError, GalvoLoop, Job, ScanPhase};
use crate::domain::Unit;
use crate::galvo::dac::DacSample;
use crate::galvo::link::{GalvoEvent, GalvoRequest};
use crate::log;

impl GalvoLoop {
    /// Takes a request (between half buffers). A refused job is returned
    /// as its [`GalvoEvent::Refused`].
    pub fn request(&mut self, request: GalvoRequest) -> Option<GalvoEvent> {
        let (seq, job) = match request {
            GalvoRequest::Stop => {
                self.stop();
                self.faulted = false;
                return None;
            }
            GalvoRequest::Point {
                seq,
                x_mm,
                y_mm,
                dwell_us,
            } => (
                seq,
                Job::Point {
                    target_mm: PointMm {
                        x_mm: f64::from(x_mm),
                        y_mm: f64::from(y_mm),
                    },
                    dwell_us,
                },
            ),
            GalvoRequest::Path {
                seq,
                path,
                mark_speed_mm_s,
            } => (seq, Job::Path(path, mark_speed_mm_s)),
        };
        let checked = if self.faulted {
            Err(GalvoError::Faulted)
        } else {
            self.check(&job)
        };
        match checked.and_then(|()| {
            self.queue
                .push_back((seq, job))
                .map_err(|_| GalvoError::QueueFull)
        }) {
            Ok(()) => None,
            Err(error) => Some(GalvoEvent::Refused { seq, error }),
        }
    }

    /// Checks a job against the current configuration.
    fn check(&self, job: &Job) -> Result<(), GalvoError> {
        match job {
            Job::Point { target_mm, .. } => self.angles_for(*target_mm).map(|_| ()),
            Job::Path(path, _) => {
                for [x_mm, y_mm] in path.bounds(Unit::GalvoMm) {
                    self.angles_for(PointMm { x_mm, y_mm })?;
                }
                Ok(())
            }
        }
    }

    /// Mirror angles (rad, f64 for planning) of a board point (mm).
    pub(super) fn angles_for(&self, target: PointMm) -> Result<[f64; 2], GalvoError> {
        // One IK (f64: per job, in the prep stage), then its DAC codes.
        let angles = self
            .planning
            .geometry
            .ik(target)
            .map_err(|_| GalvoError::Kinematics)?;
        let codes = self
            .planning
            .angles_to_codes(angles)
            .map_err(|_| GalvoError::Kinematics)?;
        if codes.clamped() {
            return Err(GalvoError::OutOfRange);
        }
        Ok([angles.x_rad, angles.y_rad])
    }

    /// New parameters, applied at the next job boundary (a new sample
    /// period at the next half-buffer boundary with no job running).
    pub fn configure(&mut self, config: GalvoConfig) {
        self.pending_config = Some(config);
    }

    /// Applies new parameters if no job is running; a refused
    /// configuration is reported and dropped.
    #[inline(never)]
    pub(super) fn apply_pending_config(&mut self, at_half_boundary: bool) -> Option<GalvoEvent> {
        let config = self.pending_config?;
        if self.active.is_some()
            || (!at_half_boundary && config.sample_period_s != self.config.sample_period_s)
        {
            return None;
        }
        self.pending_config = None;
        if config == self.config {
            return None;
        }
        match self.reconfigure(config) {
            Ok(()) => {
                log::info!("galvo: new parameters applied");
                None
            }
            Err(error) => Some(GalvoEvent::ConfigRefused(error)),
        }
    }

    /// Applies `config` in place, the mirrors holding where they are:
    /// everything is checked and built first, so a refused configuration
    /// changes nothing. The mirror model is sampled again (the `f64`
    /// matrix exponential, most of the cost on the M4) only when the
    /// mirrors or the sample rate changed; nothing else is rebuilt (the
    /// loop's buffers stay where they are, not copied).
    #[inline(never)]
    fn reconfigure(&mut self, config: GalvoConfig) -> Result<(), GalvoError> {
        self.jump_planning.check(config.method)?;
        let angles_rad = self.mirrors.end_position_rad();
        let sample_map = SampleMap::new(&config.galvo).map_err(|_| GalvoError::Kinematics)?;
        let codes = sample_map
            .angles_to_codes(angles_rad[0] as f32, angles_rad[1] as f32)
            .ok_or(GalvoError::Kinematics)?;
        let same_model = config.mirrors == self.config.mirrors
            && config.sample_period_s == self.config.sample_period_s;
        if same_model {
            self.mirrors
                .hold_at(angles_rad)
                .map_err(|_| GalvoError::Planner)?;
            self.work.rebuilds += 1;
        } else {
            let disc = config
                .mirrors
                .model()
                .and_then(|m| m.discretize(config.sample_period_s))
                .map_err(|_| GalvoError::Planner)?;
            // In place: a new integrator would be built on the stack.
            self.mirrors
                .reset(&disc, &disc, angles_rad)
                .map_err(|_| GalvoError::Planner)?;
            self.disc = disc;
            self.work.models_sampled += 1;
        }
        let ts = config.sample_period_s;
        self.sample_map = sample_map;
        self.planning = config.galvo.cast();
        self.steps.clear();
        self.running = false;
        self.jump_cursor = None;
        self.active_end_rad = angles_rad;
        self.motion = Motion::default();
        self.last = DacSample {
            x_code: codes.x.code,
            y_code: codes.y.code,
            laser: false,
        };
        self.on_delay_samples = samples_for(config.laser_on_delay_us, ts);
        self.off_delay_samples = samples_for(config.laser_off_delay_us, ts);
        self.config = config;
        Ok(())
    }

    /// Drops queued jobs and turns the laser off from the next sample; a
    /// jump in flight lands, a stroke being marked brakes along the path,
    /// and the mirrors hold.
    pub fn stop(&mut self) {
        self.trace_stop();
        self.queue.clear();
        self.joining = None;
        self.steps.clear();
        self.running = false;
        self.active = match self.active {
            Some(a) if a.phase == ScanPhase::Jumping => Some(Active {
                cancelled: true,
                ..a
            }),
            Some(a) if matches!(a.phase, ScanPhase::Marking | ScanPhase::Braking) => Some(Active {
                cancelled: true,
                phase: ScanPhase::Braking,
                ..a
            }),
            _ => None,
        };
    }

    /// Latches an underrun: laser off, jobs dropped and refused until the
    /// next `Stop`.
    pub fn underrun(&mut self) {
        self.stop();
        self.faulted = true;
    }
}
