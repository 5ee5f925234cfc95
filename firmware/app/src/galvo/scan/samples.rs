//! The per-sample state machine: what each sample of a half buffer is
//! (hold, jump, dwell, mark, brake) and the jump to each job's start.

use galvo_planner::{JumpSync, plan_xy_jump};
use kinematics_core::PointMm;

use super::{Active, GalvoError, GalvoLoop, Job, ScanPhase, samples_for};
use crate::galvo::{DacSample, GalvoEvent};

impl GalvoLoop {
    /// The sample every fill produces while nothing runs (no job, none
    /// queued, mirrors at rest, no parameters waiting): the mirrors where
    /// they rest, laser off. `None` otherwise.
    pub fn hold_sample(&mut self) -> Option<DacSample> {
        if self.active.is_some()
            || !self.queue.is_empty()
            || !self.mirrors.is_idle()
            || self.pending_config.is_some()
        {
            return None;
        }
        // An idle integrator returns its rest position and does not change.
        let [x_rad, y_rad] = self.mirrors.step();
        let (x_code, y_code) = self
            .sample_map
            .angles_to_codes(x_rad, y_rad)
            .map_or((self.last.x_code, self.last.y_code), |c| {
                (c.x.code, c.y.code)
            });
        Some(DacSample {
            x_code,
            y_code,
            laser: false,
        })
    }

    /// Fills `out` with the next samples; `on_event` gets each job's
    /// `Done` (or `Refused`, when it cannot be planned). Returns how many
    /// samples it computed: while holding, one, copied into the rest.
    pub fn fill(&mut self, out: &mut [DacSample], mut on_event: impl FnMut(GalvoEvent)) -> usize {
        if let Some(hold) = self.hold_sample() {
            out.fill(hold);
            self.last = hold;
            return out.len().min(1);
        }
        for slot in out.iter_mut() {
            self.advance(&mut on_event);
            let codes = match self.phase() {
                ScanPhase::Marking => self.mark_sample(&mut on_event),
                ScanPhase::Braking => self.brake_sample(),
                _ => {
                    let [x_rad, y_rad] = self.mirrors.step();
                    self.sample_map
                        .angles_to_codes(x_rad, y_rad)
                        .map(|c| (c.x.code, c.y.code))
                }
            };
            // Angles and marked positions stay inside the checked range;
            // on a conversion error hold the last codes rather than output
            // garbage.
            if let Some((x_code, y_code)) = codes {
                self.last.x_code = x_code;
                self.last.y_code = y_code;
            }
            self.last.laser = matches!(self.phase(), ScanPhase::Dwelling | ScanPhase::Marking);
            *slot = self.last;
            if let Some(a) = self.active.as_mut() {
                a.samples_left = a.samples_left.saturating_sub(1);
            }
        }
        out.len()
    }

    /// Moves the state machine on until the current phase has samples to
    /// produce.
    fn advance(&mut self, on_event: &mut impl FnMut(GalvoEvent)) {
        loop {
            let Some(mut a) = self.active else {
                if let Some(event) = self.apply_pending_config(false) {
                    on_event(event);
                }
                let Some((seq, job)) = self.queue.pop_front() else {
                    return;
                };
                self.active = Some(Active {
                    seq,
                    job,
                    stroke: 0,
                    phase: ScanPhase::Idle,
                    samples_left: 0,
                    cancelled: false,
                });
                if !self.jump_to_job_start(on_event) {
                    self.active = None;
                }
                continue;
            };
            match a.phase {
                ScanPhase::Marking | ScanPhase::Braking => return,
                ScanPhase::Jumping if !self.mirrors.is_idle() => return,
                ScanPhase::Jumping if a.cancelled => {
                    self.active = None;
                    return;
                }
                ScanPhase::Jumping => a.enter(ScanPhase::Settling, self.on_delay_samples),
                _ if a.samples_left > 0 => return,
                ScanPhase::Settling => match a.job {
                    Job::Point { dwell_us: 0, .. } => {
                        on_event(GalvoEvent::Done { seq: a.seq });
                        self.active = None;
                        continue;
                    }
                    Job::Point { dwell_us, .. } => a.enter(
                        ScanPhase::Dwelling,
                        samples_for(dwell_us, self.config.sample_period_s),
                    ),
                    Job::Path(path) => {
                        self.active = Some(a);
                        if !self.start_marking(path, a.stroke, on_event) {
                            self.active = None;
                        }
                        continue;
                    }
                },
                ScanPhase::Dwelling => a.enter(ScanPhase::LaserOffDelay, self.off_delay_samples),
                ScanPhase::LaserOffDelay | ScanPhase::Idle => {
                    let next_stroke = match a.job {
                        Job::Path(path) => path.stroke(a.stroke + 1).map(|_| a.stroke + 1),
                        Job::Point { .. } => None,
                    };
                    let Some(stroke) = next_stroke else {
                        on_event(GalvoEvent::Done { seq: a.seq });
                        self.active = None;
                        continue;
                    };
                    a.stroke = stroke;
                    self.active = Some(a);
                    if !self.jump_to_job_start(on_event) {
                        self.active = None;
                    }
                    continue;
                }
            }
            self.active = Some(a);
        }
    }

    /// Plans and queues the jump to the active job's point or stroke
    /// start; `false` (with `Refused`) when it cannot be planned.
    fn jump_to_job_start(&mut self, on_event: &mut impl FnMut(GalvoEvent)) -> bool {
        let Some(a) = self.active else { return false };
        let target_mm = match a.job {
            Job::Point { target_mm, .. } => target_mm,
            Job::Path(path) => match path.stroke(a.stroke) {
                Some(([x_mm, y_mm], _)) => PointMm { x_mm, y_mm },
                None => return false,
            },
        };
        let capacity = self
            .mirrors
            .x
            .free_samples()
            .min(self.mirrors.y.free_samples());
        let planned = self.angles_for(target_mm).and_then(|target_rad| {
            plan_xy_jump(
                &self.disc,
                &self.disc,
                self.mirrors.end_position_rad(),
                target_rad,
                self.config.method,
                JumpSync::Independent,
                capacity,
            )
            .and_then(|jump| self.mirrors.queue_jump(&jump))
            .map_err(|_| GalvoError::Planner)
        });
        match planned {
            Ok(()) => {
                if let Some(a) = self.active.as_mut() {
                    a.enter(ScanPhase::Jumping, 0);
                }
                true
            }
            Err(error) => {
                on_event(GalvoEvent::Refused { seq: a.seq, error });
                false
            }
        }
    }
}
