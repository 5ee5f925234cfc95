//! The two stepper task bodies: the step timer (high priority, integers
//! only) and the stepper task (low priority: requests, planning, segment
//! prep, ENABLE).

use core::sync::atomic::Ordering;

use embassy_futures::select::{Either4, select4};
use embassy_time::{Duration, Instant, Timer};

use super::config::{SEGMENT_S, StepperConfig};
use super::drive::StepperDrive;
use super::link::{StepperEvent, StepperLink, StepperRequest};
use super::motion::StepperMotion;
use crate::log;

/// How often the stepper task refills the segment queue while steps run.
pub(super) const REFILL_PERIOD: Duration = Duration::from_micros((SEGMENT_S * 0.5e6) as u64);

/// The step timer: executes prepared segments, one step event per timer
/// period. Runs at high priority (on the target an interrupt executor
/// woken by the step timer).
pub struct StepPulseTask<D> {
    pub(crate) drive: D,
    pub(crate) link: &'static StepperLink,
}

impl<D: StepperDrive> StepPulseTask<D> {
    /// Steps whatever is prepared; sleeps when nothing is.
    pub async fn run(mut self) -> ! {
        let mut enabled = false;
        self.drive.set_signals(self.link.signals());
        self.drive.set_enabled(false);
        loop {
            let want = self.link.enabled.load(Ordering::Relaxed);
            if want != enabled {
                self.drive.set_enabled(want);
                enabled = want;
            }
            // A pressed switch halts before the step (position unchanged);
            // checked only when there is a step to take.
            if self.link.has_steps() {
                self.link.limits_allow(self.drive.limits());
            }
            match self.link.step_tick() {
                Some(tick) => {
                    self.drive.step(tick.step, tick.negative);
                    self.drive.wait_ticks(tick.period_ticks).await;
                }
                None => {
                    self.link.drained.signal(());
                    self.link.ready.wait().await;
                    self.drive.set_signals(self.link.signals());
                    self.drive.restart();
                }
            }
        }
    }
}

/// The stepper task: moves in, segments out, events back.
pub struct StepperTask {
    pub(crate) link: &'static StepperLink,
    pub(crate) config: StepperConfig,
}

/// The stepper task's state between wake-ups.
pub(super) struct Running {
    pub(super) motion: StepperMotion,
    /// A stop is decelerating.
    pub(super) stopping: bool,
    /// Parameters to apply once at rest.
    pending_config: Option<StepperConfig>,
    /// A move that arrived during a stop: queued once at rest.
    pub(super) deferred: Option<StepperRequest>,
    /// When the axes came to rest (for the ENABLE release).
    rest_since: Option<Instant>,
}

impl StepperTask {
    /// Serves the link until the end of time; ends at once (logged) if the
    /// default parameters are refused.
    pub async fn run(self) {
        let motion = match StepperMotion::new(self.config) {
            Ok(motion) => motion,
            Err(e) => {
                log::error!("stepper task not started: {:?}", e);
                return;
            }
        };
        let link = self.link;
        link.set_signals(self.config.signals);
        link.attach();
        let mut state = Running {
            motion,
            stopping: false,
            pending_config: None,
            deferred: None,
            rest_since: Some(Instant::now()),
        };
        loop {
            state.step(link).await;
            let busy = state.rest_since.is_none();
            let wait = if busy {
                REFILL_PERIOD
            } else {
                Duration::from_millis(50)
            };
            let woke = select4(
                link.requests.receive(),
                link.config.wait(),
                link.drained.wait(),
                Timer::after(wait),
            );
            match woke.await {
                Either4::First(request) => state.request(request, link).await,
                Either4::Second(config) => state.configure(config, link),
                Either4::Third(()) | Either4::Fourth(()) => {}
            }
        }
    }
}

impl Running {
    /// Halts, refills, reports arrivals and rests, releases ENABLE.
    async fn step(&mut self, link: &StepperLink) {
        if link.take_halt() {
            let steps = link.position_steps();
            self.motion.rest_at(steps);
            self.stopping = false;
            self.deferred = None;
            log::info!("stepper: halted");
            let axes = link.take_tripped();
            let event = if axes != 0 {
                StepperEvent::LimitHit { axes, steps }
            } else {
                StepperEvent::Stopped { steps }
            };
            link.events.send(event).await;
        }
        if let Some(percent) = link.take_feed_override() {
            self.motion.set_feed_percent(percent);
        }
        self.refill(link);
        if let Some(seq) = self.motion.take_started() {
            link.events.send(StepperEvent::Taken { seq }).await;
        }
        let idle = link.is_idle();
        if let Some(seq) = self.motion.take_arrived(idle) {
            let steps = link.position_steps();
            link.events.send(StepperEvent::Arrived { seq, steps }).await;
        }
        if idle && self.motion.is_planned_out() {
            self.at_rest(link).await;
        }
    }

    /// Tops the step timer's queue up with prepared segments.
    pub(super) fn refill(&mut self, link: &StepperLink) {
        let mut added = 0;
        while !link.with_queue(|q| q.is_full()) {
            let Some(segment) = self.motion.next_segment() else {
                break;
            };
            // Room checked above; only the step timer takes from the queue.
            if link.with_queue(|q| q.push_back(segment)).is_ok() {
                added += 1;
            }
        }
        if added > 0 {
            self.rest_since = None;
            link.enabled.store(true, Ordering::Relaxed);
            link.ready.signal(());
        }
    }

    async fn at_rest(&mut self, link: &StepperLink) {
        let steps = link.position_steps();
        if self.stopping {
            self.stopping = false;
            self.motion.rest_at(steps);
            link.events.send(StepperEvent::Stopped { steps }).await;
        }
        if let Some(config) = self.pending_config.take() {
            self.apply(config, link);
        }
        if let Some(request) = self.deferred.take() {
            self.move_to(request, link).await;
        }
        let now = Instant::now();
        let since = *self.rest_since.get_or_insert(now);
        let release_ms = self.motion.config().idle_release_ms;
        if release_ms > 0
            && now.saturating_duration_since(since) >= Duration::from_millis(u64::from(release_ms))
            && link.enabled.swap(false, Ordering::Relaxed)
        {
            log::info!("stepper: drivers released after {} ms at rest", release_ms);
            link.ready.signal(());
        }
    }

    fn apply(&mut self, config: StepperConfig, link: &StepperLink) {
        match self.motion.configure(config) {
            Ok(()) => link.set_signals(config.signals),
            Err(e) => log::error!("stepper: parameters refused: {:?}", e),
        }
    }

    async fn request(&mut self, request: StepperRequest, link: &StepperLink) {
        match request {
            StepperRequest::MoveTo { .. } if self.stopping => {
                // Planned from where the stop comes to rest.
                self.deferred = Some(request);
            }
            StepperRequest::MoveTo { .. } => self.move_to(request, link).await,
            StepperRequest::Halt => link.halt(),
            StepperRequest::Stop => {
                link.with_queue_executing(|q, e| self.motion.stop(q, e));
                self.deferred = None;
                self.stopping = true;
                self.refill(link);
            }
            StepperRequest::Home => {
                let event = match self.home(link).await {
                    Ok(steps) => StepperEvent::Homed { steps },
                    Err(why) => StepperEvent::HomingFailed {
                        why,
                        steps: link.position_steps(),
                    },
                };
                link.events.send(event).await;
            }
            StepperRequest::Hold => {
                link.with_queue_executing(|q, e| self.motion.hold(q, e));
                self.deferred = None;
                self.stopping = true;
                self.refill(link);
            }
            StepperRequest::FeedOverride { percent } => self.motion.set_feed_percent(percent),
            StepperRequest::Junction { deviation_deg } => {
                self.motion.set_junction_deg(deviation_deg)
            }
            StepperRequest::Resume => {
                if let Err(e) = self.motion.resume(link.position_steps()) {
                    log::warning!("stepper: resume refused: {:?}", e);
                }
            }
        }
    }

    async fn move_to(&mut self, request: StepperRequest, link: &StepperLink) {
        let StepperRequest::MoveTo {
            seq,
            point,
            shape,
            feed_mm_s,
        } = request
        else {
            return;
        };
        match self.motion.move_to(seq, point, shape, feed_mm_s) {
            Ok(true) => link.events.send(StepperEvent::Taken { seq }).await,
            Ok(false) => {}
            Err(why) => {
                log::warning!("stepper: move {} refused: {:?}", seq, why);
                link.events.send(StepperEvent::Refused { seq, why }).await;
            }
        }
    }

    fn configure(&mut self, config: StepperConfig, link: &StepperLink) {
        if link.is_idle() && self.motion.is_planned_out() {
            self.apply(config, link);
        } else {
            self.pending_config = Some(config);
        }
    }
}
