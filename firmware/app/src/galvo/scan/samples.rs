//! The per-sample state machine: what each sample of a half buffer is
//! (hold, jump, dwell, mark, brake) and the jump to each job's start.

use galvo_planner::Error as PlannerError;

use super::build::samples_for;
use super::runs::queue_jump;
use super::{Active, GalvoError, GalvoLoop, Job, ScanPhase};
use crate::domain::Unit;
use crate::galvo::dac::DacSample;
use crate::galvo::link::GalvoEvent;

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

    /// Fills `out` with the next samples, preparing (planning) each step
    /// on demand when [`Self::prep`] has not: the host-side API (tests,
    /// benches), one call per half. `on_event` gets each job's `Done` (or
    /// `Refused`, when it cannot be planned). Returns how many samples it
    /// computed: while holding, one, copied into the rest.
    pub fn fill(&mut self, out: &mut [DacSample], mut on_event: impl FnMut(GalvoEvent)) -> usize {
        self.fill_with(out, &mut on_event, true)
    }

    /// The refill: fills `out` with the next samples from the steps
    /// [`Self::prep`] prepared, planning nothing (bounded work per
    /// sample). A step that is not prepared yet holds the mirrors, laser
    /// off, until a later refill finds it prepared. `on_event` and the
    /// result as for [`Self::fill`].
    #[inline(never)]
    pub fn refill(&mut self, out: &mut [DacSample], mut on_event: impl FnMut(GalvoEvent)) -> usize {
        self.fill_with(out, &mut on_event, false)
    }

    fn fill_with(
        &mut self,
        out: &mut [DacSample],
        on_event: &mut impl FnMut(GalvoEvent),
        on_demand: bool,
    ) -> usize {
        self.work.refills += 1;
        if let Some(hold) = self.hold_sample() {
            self.work.held += out.len() as u32;
            out.fill(hold);
            self.last = hold;
            return out.len().min(1);
        }
        // Run by run: each phase produces as many samples as it has (or
        // the half takes) in a tight loop of its own (scan/runs.rs).
        let mut done = 0;
        while let Some(rest) = out.get_mut(done..).filter(|rest| !rest.is_empty()) {
            let n = if self.advance(on_event, on_demand) == Advance::Unprepared {
                self.unprepared_samples = self.unprepared_samples.saturating_add(1);
                let one = rest.len().min(1);
                self.held_run(&mut rest[..one])
            } else {
                self.phase_run(rest, on_event)
            };
            done += n.max(1);
        }
        out.len()
    }

    /// Moves the state machine on until the current phase has samples to
    /// produce, or the next step is not prepared (`on_demand`: prepares
    /// it).
    fn advance(&mut self, on_event: &mut impl FnMut(GalvoEvent), on_demand: bool) -> Advance {
        // The common case, without copying the job out and back: the
        // current phase still has samples (the loop's first pass below
        // returns at once in these cases too).
        if let Some(a) = self.active.as_ref() {
            let busy = match a.phase {
                ScanPhase::Marking | ScanPhase::Braking => true,
                ScanPhase::Jumping => !self.mirrors.is_idle(),
                _ => a.samples_left > 0,
            };
            if busy {
                return Advance::Ready;
            }
        }
        loop {
            let settled = match self.active {
                None => self.start_queued(on_event, on_demand),
                Some(a) => self.next_phase(a, on_event, on_demand),
            };
            if let Some(advance) = settled {
                return advance;
            }
        }
    }

    /// No job runs: applies waiting parameters and starts the queue's
    /// first job. `Some` when [`Self::advance`] is done, `None` to go on.
    #[inline(always)]
    fn start_queued(
        &mut self,
        on_event: &mut impl FnMut(GalvoEvent),
        on_demand: bool,
    ) -> Option<Advance> {
        if self.pending_config.is_some() && !on_demand {
            // New parameters wait for the next half boundary
            // (`GalvoLoop::run` applies them there): no rebuild inside
            // the refill. The mirrors hold, laser off, until then.
            return Some(Advance::Ready);
        }
        if let Some(event) = self.apply_pending_config(false) {
            on_event(event);
        }
        let Some(&(seq, job)) = self.queue.front() else {
            return Some(Advance::Ready);
        };
        match self.start_step(seq, job, 0, on_demand, on_event) {
            StepStart::Unprepared => return Some(Advance::Unprepared),
            StepStart::Started | StepStart::Refused => {
                self.queue.pop_front();
            }
        }
        None
    }

    /// Job `a` (a copy of the active one) moves on from its phase when
    /// the phase has no samples left. `Some` when [`Self::advance`] is
    /// done, `None` to go on.
    #[inline(always)]
    fn next_phase(
        &mut self,
        mut a: Active,
        on_event: &mut impl FnMut(GalvoEvent),
        on_demand: bool,
    ) -> Option<Advance> {
        match a.phase {
            ScanPhase::Marking | ScanPhase::Braking => return Some(Advance::Ready),
            ScanPhase::Jumping if !self.mirrors.is_idle() => return Some(Advance::Ready),
            ScanPhase::Jumping if a.cancelled => {
                self.active = None;
                return Some(Advance::Ready);
            }
            ScanPhase::Jumping => a.enter(ScanPhase::Settling, self.on_delay_samples),
            _ if a.samples_left > 0 => return Some(Advance::Ready),
            ScanPhase::Settling => match a.job {
                Job::Point { dwell_us: 0, .. } => {
                    on_event(GalvoEvent::Done { seq: a.seq });
                    self.active = None;
                    return None;
                }
                Job::Point { dwell_us, .. } => a.enter(
                    ScanPhase::Dwelling,
                    samples_for(dwell_us, self.config.sample_period_s),
                ),
                Job::Path(path, _) => {
                    self.active = Some(a);
                    if !self.start_marking(path, a.stroke, on_event) {
                        self.active = None;
                    }
                    return None;
                }
            },
            ScanPhase::Dwelling => a.enter(ScanPhase::LaserOffDelay, self.off_delay_samples),
            ScanPhase::LaserOffDelay | ScanPhase::Idle => {
                return self.next_stroke(a, on_event, on_demand);
            }
        }
        self.active = Some(a);
        None
    }

    /// Job `a`'s step is over (laser off): starts its next stroke, or
    /// reports it done. `Some` when [`Self::advance`] is done, `None` to go
    /// on.
    #[inline(always)]
    fn next_stroke(
        &mut self,
        a: Active,
        on_event: &mut impl FnMut(GalvoEvent),
        on_demand: bool,
    ) -> Option<Advance> {
        let next_stroke = match a.job {
            Job::Path(path, _) => path
                .stroke(a.stroke + 1, Unit::GalvoMm)
                .map(|_| a.stroke + 1),
            Job::Point { .. } => None,
        };
        let Some(stroke) = next_stroke else {
            on_event(GalvoEvent::Done { seq: a.seq });
            self.active = None;
            return None;
        };
        self.active = Some(a);
        match self.start_step(a.seq, a.job, stroke, on_demand, on_event) {
            // Holds here, laser off, until the stroke is prepared.
            StepStart::Unprepared => return Some(Advance::Unprepared),
            StepStart::Started => {}
            StepStart::Refused => self.active = None,
        }
        None
    }

    /// Starts step `stroke` of job `(seq, job)` from its prepared plan,
    /// where it lies: queues the jump; the stroke is marked from the
    /// step's slot. Plans it first only when `on_demand`; otherwise an
    /// unprepared step waits.
    fn start_step(
        &mut self,
        seq: u32,
        job: Job,
        stroke: usize,
        on_demand: bool,
        on_event: &mut impl FnMut(GalvoEvent),
    ) -> StepStart {
        if self.running {
            // The step before this one is over.
            self.steps.drop_front();
            self.running = false;
        }
        for _ in 0..2 {
            if !self.next_prepared_is(seq, &job, stroke) {
                // None prepared, or not this one: prepare again from here.
                self.steps.clear();
                if !on_demand {
                    return StepStart::Unprepared;
                }
                self.prep();
                if !self.next_prepared_is(seq, &job, stroke) {
                    return StepStart::Unprepared;
                }
            }
            let Some(step) = self.steps.get(0) else {
                return StepStart::Unprepared;
            };
            let end_rad = step.end_rad;
            // `Err(None)`: planned from somewhere the mirrors are not (stale).
            let queued = match &step.jump {
                Err(error) => Err(Some(*error)),
                Ok(jump) => match queue_jump(
                    &mut self.mirrors,
                    &mut self.jump_codes,
                    &mut self.jump_cursor,
                    jump,
                    step.jump_codes.as_ref(),
                ) {
                    Ok(()) => Ok(()),
                    Err(PlannerError::DiscontinuousMove) => Err(None),
                    Err(_) => Err(Some(GalvoError::Planner)),
                },
            };
            match queued {
                Ok(()) => {
                    self.active = Some(Active {
                        seq,
                        job,
                        stroke,
                        phase: ScanPhase::Jumping,
                        samples_left: 0,
                        cancelled: false,
                    });
                    self.running = true;
                    self.active_end_rad = end_rad;
                    self.work.steps_started += 1;
                    return StepStart::Started;
                }
                Err(None) => self.steps.clear(),
                Err(Some(error)) => {
                    // Refused: the steps after it were planned from where
                    // the mirrors stay.
                    self.steps.drop_front();
                    on_event(GalvoEvent::Refused { seq, error });
                    return StepStart::Refused;
                }
            }
        }
        StepStart::Unprepared
    }
}

/// Whether the state machine has its next samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Advance {
    /// The current phase has samples (or nothing runs).
    Ready,
    /// The next step is not prepared: hold, laser off.
    Unprepared,
}

/// How starting a step went.
enum StepStart {
    /// Its jump is queued; the job runs it.
    Started,
    /// It could not be planned (`Refused` reported): the job ends.
    Refused,
    /// Not prepared yet: try again at a later sample.
    Unprepared,
}
