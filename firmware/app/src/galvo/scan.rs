//! The loop body: job queue (points and marked paths), jump planning,
//! per-sample state update, marking, laser timing and DAC mapping.

use core::sync::atomic::Ordering;

use galvo_planner::blocks::LoopIntegrator;
use galvo_planner::{Discrete, Method};
use kinematics_core::{Galvo, SampleMap};

use self::planning::Planning;
use self::ring::StepRing;
use self::state::{Joining, JumpCodes, Motion, Trace};
use self::types::{Active, JOB_QUEUE, Job, PREP_PER_HALF};
pub use self::types::{GalvoConfig, GalvoError, MAX_HALF_LEN, ScanPhase};
use super::dac::{DacSample, DacStream, Half};
use super::link::{GalvoEvent, GalvoLink};
use crate::laser_gate::LaserGate;
use crate::log;

/// The galvo loop's state. Build with [`GalvoLoop::new`], then
/// [`GalvoLoop::run`] (or drive [`GalvoLoop::request`] and
/// [`GalvoLoop::fill`] directly).
pub struct GalvoLoop {
    config: GalvoConfig,
    /// `config.galvo` checked once for the per-sample f32 path.
    sample_map: SampleMap,
    planning: Galvo<f64>,
    disc: Discrete<3>,
    mirrors: LoopIntegrator,
    /// The running step (when `running`) and the steps planned ahead of
    /// the refill by [`GalvoLoop::prep`].
    steps: StepRing,
    /// Whether the oldest of `steps` is the running one.
    running: bool,
    /// The running jump's codes (prepared), and the next one to output
    /// (`None`: the jump is stepped on the integrator).
    jump_codes: JumpCodes,
    jump_cursor: Option<usize>,
    /// Where the running step leaves the mirrors, rad.
    active_end_rad: [f64; 2],
    /// Work since the last half buffer (the cost model's input).
    work: super::cost::LoopWork,
    /// Samples held dark for want of a prepared step.
    unprepared_samples: u32,
    motion: Motion,
    queue: heapless::Deque<(u32, Job), JOB_QUEUE>,
    active: Option<Active>,
    last: DacSample,
    /// Latched by an underrun: jobs are refused until `Stop`.
    faulted: bool,
    /// Parameters to apply at the next job boundary.
    pending_config: Option<GalvoConfig>,
    on_delay_samples: u32,
    off_delay_samples: u32,
    /// How jumps are planned on this board ([`DacStream::F64_PLANNING`]).
    jump_planning: Planning,
    /// A continuation stroke joined to the running one, its `Done` due
    /// when the sampler reaches its blocks ([`join`]).
    joining: Option<Joining>,
    /// Where marking was after each of the last halves, newest first.
    trace: Trace,
}

impl GalvoLoop {
    /// What the mirrors and laser are doing now.
    pub fn phase(&self) -> ScanPhase {
        // By reference: this runs several times per sample.
        self.active.as_ref().map_or(ScanPhase::Idle, |a| a.phase)
    }

    /// Jobs waiting behind the current one.
    pub fn queued_points(&self) -> usize {
        self.queue.len()
    }

    /// Whether a half buffer of `half` samples holds the DAC's halves.
    pub fn fits(dac: &impl DacStream, half: usize) -> bool {
        (1..=half.min(MAX_HALF_LEN)).contains(&dac.half_len())
    }

    /// Runs the loop forever: requests between half buffers, one half per
    /// wake-up, laser through the master `gate`.
    ///
    /// * A close of the gate (by anyone: `stop`, a fault, a new run) is a
    ///   stop that cannot get lost in a full queue: queued jobs are
    ///   dropped and the laser stays off; halves computed before it stay
    ///   dark. The loop opens the gate only for lit samples of jobs taken
    ///   after the last close.
    /// * An underrun closes the gate at once, drops the queued jobs (also
    ///   those still in the request channel) and is reported; jobs are
    ///   refused until the next `Stop`.
    /// * Holding still, the loop lets the DAC replay the hold both halves
    ///   already hold: no work, so an idle loop cannot underrun.
    /// * A job's `Done` is reported once the DAC has output its last
    ///   sample (the loop computes up to two halves ahead), so the
    ///   sequencer can close the gate when a pattern ends without cutting
    ///   its last dwell short.
    pub async fn run<D: DacStream>(
        &mut self,
        dac: &mut D,
        link: &GalvoLink,
        gate: &LaserGate,
    ) -> ! {
        let mut half = [DacSample::default(); MAX_HALF_LEN];
        self.run_with(dac, link, gate, &mut half).await
    }

    /// [`Self::run`], computing each half in `half` (the caller's memory:
    /// a board keeps it in a `static`, see [`GalvoMemory`](crate::galvo::GalvoMemory), so the task's
    /// future does not hold it). Halves of the DAC's
    /// [`DacStream::half_len`] samples, at most `half.len()` (a shorter
    /// buffer shortens every half: check with [`Self::fits`] first).
    pub async fn run_with<D: DacStream, const HALF: usize>(
        &mut self,
        dac: &mut D,
        link: &GalvoLink,
        gate: &LaserGate,
        half: &mut [DacSample; HALF],
    ) -> ! {
        link.bisection.store(D::F64_PLANNING, Ordering::Relaxed);
        self.jump_planning = Planning::of::<D>();
        if let Err(e) = self.jump_planning.check(self.config.method) {
            log::error!("galvo: {}; planning time-optimal", e);
            self.config.method = Method::TimeOptimal;
        }
        link.attach();
        let n = dac.half_len().clamp(1, MAX_HALF_LEN).min(HALF).max(1);
        let mut period_s = self.config.sample_period_s;
        let mut generation = gate.generation();
        // `Done` events waiting for their samples to be output, with the
        // half-buffer hand-overs still to come.
        let mut drawing: heapless::Deque<(GalvoEvent, u8), DONE_QUEUE> = heapless::Deque::new();
        dac.set_sample_period(period_s);
        loop {
            self.work = super::cost::LoopWork::default();
            let now = gate.generation();
            if now != generation {
                self.stop();
                // The stopped run's points were cut short.
                drawing.clear();
                generation = now;
            }
            self.take_requests(link);
            self.report_stopped(link);
            if let Some(config) = link.config.try_take() {
                self.configure(config);
            }
            if let Some(event) = self.apply_pending_config(true) {
                let _ = link.events.try_send(event);
            }
            if self.config.sample_period_s != period_s {
                period_s = self.config.sample_period_s;
                dac.set_sample_period(period_s);
            }
            link.halves.fetch_add(1, Ordering::Relaxed);
            if let Some(hold) = self.hold_sample()
                && dac.holds(hold)
            {
                link.publish(self.phase(), self.queue.len());
                dac.repeat_half().await;
                release_drawn(&mut drawing, link);
                continue;
            }
            // Plan ahead, outside the refill: the refill only steps plans.
            self.prep_up_to(PREP_PER_HALF);
            let out = &mut half[..n];
            let computed = self.refill(out, |event| hold_done(&mut drawing, link, event));
            self.trace_half();
            link.publish(self.phase(), self.queue.len());
            if !link.laser_allowed() {
                // `laser off`: the mirrors still move, dark.
                out.iter_mut().for_each(|s| s.laser = false);
            }
            if out.iter().any(|s| s.laser) {
                // Refused (the half stays dark) when the gate closed since.
                gate.open(generation);
            }
            let written = dac
                .write_half(Half {
                    samples: out,
                    generation,
                    computed,
                    work: self.work,
                })
                .await;
            link.publish_refill(dac.worst_refill());
            release_drawn(&mut drawing, link);
            if let Err(underrun) = written {
                generation = gate.close();
                drawing.clear();
                link.underruns.fetch_add(underrun.halves, Ordering::Relaxed);
                log::warning!(
                    "galvo: underrun ({} halves late), laser off",
                    underrun.halves
                );
                self.underrun();
                self.take_requests(link);
                let _ = link.events.try_send(GalvoEvent::Underrun(underrun));
            }
        }
    }
}

impl GalvoLoop {
    /// Takes every request waiting in the link; refusals go back as events.
    // Out of line (as the other per-half stages): the async run loop's
    // frame, which nests on whatever stack the galvo interrupt
    // interrupts, holds none of their temporaries.
    #[inline(never)]
    fn take_requests(&mut self, link: &GalvoLink) {
        while let Ok(request) = link.requests.try_receive() {
            if let Some(event) = self.request(request) {
                let _ = link.events.try_send(event);
            }
        }
    }
}

/// `Done` events held until their samples are out.
const DONE_QUEUE: usize = 8;

/// Reports an event of a computed half: at once, or for `Done`, once the
/// DAC has output the half after this one (held in `drawing`).
fn hold_done(
    drawing: &mut heapless::Deque<(GalvoEvent, u8), DONE_QUEUE>,
    link: &GalvoLink,
    event: GalvoEvent,
) {
    match event {
        // Output when the half after this one starts.
        GalvoEvent::Done { .. } => {
            if let Err((event, _)) = drawing.push_back((event, 3)) {
                let _ = link.events.try_send(event);
            }
        }
        _ => {
            let _ = link.events.try_send(event);
        }
    }
}

/// Counts one half-buffer hand-over down for the held `Done` events and
/// reports those whose samples the DAC has now output.
fn release_drawn(drawing: &mut heapless::Deque<(GalvoEvent, u8), DONE_QUEUE>, link: &GalvoLink) {
    for (_, halves) in drawing.iter_mut() {
        *halves = halves.saturating_sub(1);
    }
    while let Some((event, 0)) = drawing.front().copied() {
        drawing.pop_front();
        let _ = link.events.try_send(event);
    }
}

mod build;
mod jobs;
mod join;
mod mark;
pub(super) mod memory;
mod planning;
mod prep;
mod ring;
mod runs;
mod samples;
mod state;
#[cfg(test)]
mod tests;
mod trace;
pub(super) mod types;
