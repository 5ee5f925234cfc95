//! The loop body: point queue, jump planning, per-sample state update,
//! laser timing and DAC mapping.

use core::fmt;
use core::sync::atomic::Ordering;

use galvo_planner::{Discrete, JumpSync, Method, RigidParams, XyStepper, plan_xy_jump};

use crate::settings::GalvoSettings;
use kinematics_core::{Galvo, MirrorAngles, PointMm};

use super::{DacSample, DacStream, GalvoEvent, GalvoLink, GalvoRequest};
use crate::log;

/// Jump input samples the stepper holds per axis (10.24 ms at 100 kHz,
/// longer than any full-range time-optimal jump of the reference galvo).
pub const STEPPER_CAPACITY: usize = 1024;
/// Longest half buffer the loop fills, samples.
pub const MAX_HALF_LEN: usize = 512;
/// Points queued inside the loop (beyond the request channel).
const POINT_QUEUE: usize = 4;

/// Galvo loop parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GalvoConfig {
    /// DAC sample period, s (10 µs = 100 kHz).
    pub sample_period_s: f64,
    /// Mirror geometry and DAC mapping.
    pub galvo: Galvo<f32>,
    /// Mirror drive model (both axes), for jump planning.
    pub mirrors: RigidParams,
    /// Jump planner: time-optimal (default) or the patent's bisection.
    pub method: Method,
    /// Hold after a jump lands, laser still off (mirror settling), µs.
    pub laser_on_delay_us: u32,
    /// Hold after the laser turns off, before the next jump, µs.
    pub laser_off_delay_us: u32,
}

impl Default for GalvoConfig {
    /// The default galvo parameters ([`GalvoSettings::default`]): 100 kHz,
    /// SPEC geometry and DAC span, reference mirror drive, time-optimal
    /// jumps, 100 µs laser delays.
    fn default() -> Self {
        super::config_from(&GalvoSettings::default())
    }
}

/// Why the loop cannot be built or a point cannot be visited.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GalvoError {
    /// Galvo kinematics refused the point (non-finite, invalid geometry).
    Kinematics,
    /// The point is outside the DAC's range.
    OutOfRange,
    /// The jump planner refused (invalid model, jump too long for the
    /// stepper's buffer).
    Planner,
    /// More points than the loop queues.
    QueueFull,
    /// An underrun latched the laser off; a `Stop` clears it.
    Faulted,
}

impl fmt::Display for GalvoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            GalvoError::Kinematics => "galvo kinematics refused the point",
            GalvoError::OutOfRange => "point is outside the galvo's DAC range",
            GalvoError::Planner => "jump planner refused the move",
            GalvoError::QueueFull => "galvo point queue is full",
            GalvoError::Faulted => "galvo underrun: send stop before new points",
        })
    }
}

/// What the mirrors and laser are doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Phase {
    /// Holding, laser off, nothing queued.
    Idle,
    /// Jumping to the point, laser off.
    Jumping,
    /// Landed; laser-on delay.
    Settling,
    /// Laser on at the point.
    Dwelling,
    /// Laser off; laser-off delay before the next jump.
    LaserOffDelay,
}

/// A queued point (converted to angles when its jump starts, with the
/// configuration in force then).
#[derive(Debug, Clone, Copy)]
struct Point {
    seq: u32,
    target_mm: PointMm,
    dwell_us: u32,
}

/// The point being visited.
#[derive(Debug, Clone, Copy)]
struct Active {
    seq: u32,
    phase: Phase,
    /// Samples left in a timed phase.
    samples_left: u32,
    dwell_samples: u32,
    /// `stop` arrived during the jump: hold after landing, no dwell.
    cancelled: bool,
}

/// The galvo loop's state. Build with [`GalvoLoop::new`], then
/// [`GalvoLoop::run`] (or drive [`GalvoLoop::request`] and
/// [`GalvoLoop::fill`] directly).
pub struct GalvoLoop {
    config: GalvoConfig,
    planning: Galvo<f64>,
    disc: Discrete<3>,
    mirrors: XyStepper<3, STEPPER_CAPACITY>,
    queue: heapless::Deque<Point, POINT_QUEUE>,
    active: Option<Active>,
    last: DacSample,
    /// Latched by an underrun: points are refused until `Stop`.
    faulted: bool,
    /// Parameters to apply at the next point boundary.
    pending_config: Option<GalvoConfig>,
    on_delay_samples: u32,
    off_delay_samples: u32,
}

fn samples_for(us: u32, ts_s: f64) -> u32 {
    // Whole samples, rounded up: a delay is never shorter than asked.
    libm::ceil(f64::from(us) * 1e-6 / ts_s - 1e-9).max(0.0) as u32
}

impl GalvoLoop {
    /// A loop holding the mirrors at the centre, laser off.
    ///
    /// Errors: [`GalvoError::Planner`] for an invalid mirror model or
    /// sample period, [`GalvoError::Kinematics`] for invalid geometry.
    pub fn new(config: GalvoConfig) -> Result<Self, GalvoError> {
        Self::holding_at(config, [0.0, 0.0])
    }

    /// A loop holding the mirrors at `angles_rad`, laser off.
    fn holding_at(config: GalvoConfig, angles_rad: [f64; 2]) -> Result<Self, GalvoError> {
        let disc = config
            .mirrors
            .model()
            .and_then(|m| m.discretize(config.sample_period_s))
            .map_err(|_| GalvoError::Planner)?;
        let mirrors = XyStepper::new(&disc, &disc, angles_rad).map_err(|_| GalvoError::Planner)?;
        let [x_rad, y_rad] = angles_rad;
        let centre = config
            .galvo
            .angles_to_codes(MirrorAngles {
                x_rad: x_rad as f32,
                y_rad: y_rad as f32,
            })
            .map_err(|_| GalvoError::Kinematics)?;
        let ts = config.sample_period_s;
        Ok(Self {
            planning: config.galvo.cast(),
            disc,
            mirrors,
            queue: heapless::Deque::new(),
            active: None,
            last: DacSample {
                x_code: centre.x.code,
                y_code: centre.y.code,
                laser: false,
            },
            faulted: false,
            pending_config: None,
            on_delay_samples: samples_for(config.laser_on_delay_us, ts),
            off_delay_samples: samples_for(config.laser_off_delay_us, ts),
            config,
        })
    }

    /// What the mirrors and laser are doing now.
    pub fn phase(&self) -> Phase {
        self.active.map_or(Phase::Idle, |a| a.phase)
    }

    /// Points waiting behind the current one.
    pub fn queued_points(&self) -> usize {
        self.queue.len()
    }

    /// Takes a request (between half buffers). A refused point is
    /// returned as its [`GalvoEvent::Refused`].
    pub fn request(&mut self, request: GalvoRequest) -> Option<GalvoEvent> {
        match request {
            GalvoRequest::Stop => {
                self.stop();
                self.faulted = false;
                None
            }
            GalvoRequest::Point { seq, .. } if self.faulted => Some(GalvoEvent::Refused {
                seq,
                error: GalvoError::Faulted,
            }),
            GalvoRequest::Point {
                seq,
                x_mm,
                y_mm,
                dwell_us,
            } => match self.point(seq, x_mm, y_mm, dwell_us) {
                Ok(_) if self.queue.is_full() => Some(GalvoEvent::Refused {
                    seq,
                    error: GalvoError::QueueFull,
                }),
                Ok(_) => match self.queue.push_back(Point {
                    seq,
                    target_mm: PointMm {
                        x_mm: f64::from(x_mm),
                        y_mm: f64::from(y_mm),
                    },
                    dwell_us,
                }) {
                    Ok(()) => None,
                    Err(_) => Some(GalvoEvent::Refused {
                        seq,
                        error: GalvoError::QueueFull,
                    }),
                },
                Err(error) => Some(GalvoEvent::Refused { seq, error }),
            },
        }
    }

    /// Checks a point (mm) and converts it to mirror angles (rad, f64 for
    /// planning).
    fn angles_for(&self, target: PointMm) -> Result<[f64; 2], GalvoError> {
        let codes = self
            .planning
            .board_to_codes(target)
            .map_err(|_| GalvoError::Kinematics)?;
        if codes.clamped() {
            return Err(GalvoError::OutOfRange);
        }
        let angles = self
            .planning
            .geometry
            .ik(target)
            .map_err(|_| GalvoError::Kinematics)?;
        Ok([angles.x_rad, angles.y_rad])
    }

    /// Checks a requested point against the current configuration.
    fn point(&self, _seq: u32, x_mm: f32, y_mm: f32, _dwell_us: u32) -> Result<(), GalvoError> {
        self.angles_for(PointMm {
            x_mm: f64::from(x_mm),
            y_mm: f64::from(y_mm),
        })
        .map(|_| ())
    }

    /// New parameters, applied at the next point boundary (a new sample
    /// period at the next half-buffer boundary with no point running).
    pub fn configure(&mut self, config: GalvoConfig) {
        self.pending_config = Some(config);
    }

    /// Applies new parameters if no point is running (else at the next
    /// point boundary; a new sample period only at a half-buffer
    /// boundary, so every half has one period); a refused configuration is
    /// reported and dropped.
    fn apply_pending_config(&mut self, at_half_boundary: bool) -> Option<GalvoEvent> {
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
        match Self::holding_at(config, self.mirrors.end_position_rad()) {
            Ok(mut fresh) => {
                fresh.queue = core::mem::take(&mut self.queue);
                fresh.faulted = self.faulted;
                *self = fresh;
                log::info!("galvo: new parameters applied");
                None
            }
            Err(error) => Some(GalvoEvent::ConfigRefused(error)),
        }
    }

    /// Drops queued points and turns the laser off from the next sample;
    /// a jump in flight lands and holds.
    pub fn stop(&mut self) {
        self.queue.clear();
        self.active = match self.active {
            Some(a) if a.phase == Phase::Jumping => Some(Active {
                cancelled: true,
                ..a
            }),
            _ => None,
        };
    }

    /// Fills `out` with the next samples; `on_event` gets each point's
    /// `Done` (or `Refused`, when its jump cannot be planned).
    pub fn fill(&mut self, out: &mut [DacSample], mut on_event: impl FnMut(GalvoEvent)) {
        for slot in out.iter_mut() {
            self.advance(&mut on_event);
            let [x_rad, y_rad] = self.mirrors.step();
            let laser = self.phase() == Phase::Dwelling;
            // The stepper's angles stay between planned rest points, all
            // inside the DAC range; on a conversion error hold the last
            // codes rather than output garbage.
            if let Ok(codes) = self
                .config
                .galvo
                .angles_to_codes(MirrorAngles { x_rad, y_rad })
            {
                self.last.x_code = codes.x.code;
                self.last.y_code = codes.y.code;
            }
            self.last.laser = laser;
            *slot = self.last;
            if let Some(a) = self.active.as_mut() {
                a.samples_left = a.samples_left.saturating_sub(1);
            }
        }
    }

    /// Moves the state machine on until the current phase has samples to
    /// produce.
    fn advance(&mut self, on_event: &mut impl FnMut(GalvoEvent)) {
        loop {
            let Some(mut a) = self.active else {
                if let Some(event) = self.apply_pending_config(false) {
                    on_event(event);
                }
                let Some(point) = self.queue.pop_front() else {
                    return;
                };
                self.start(point, on_event);
                continue;
            };
            match a.phase {
                Phase::Jumping if !self.mirrors.is_idle() => return,
                Phase::Jumping if a.cancelled => {
                    self.active = None;
                    return;
                }
                Phase::Jumping => a.enter(Phase::Settling, self.on_delay_samples),
                _ if a.samples_left > 0 => return,
                Phase::Settling if a.dwell_samples == 0 => {
                    on_event(GalvoEvent::Done { seq: a.seq });
                    self.active = None;
                    continue;
                }
                Phase::Settling => a.enter(Phase::Dwelling, a.dwell_samples),
                Phase::Dwelling => a.enter(Phase::LaserOffDelay, self.off_delay_samples),
                Phase::LaserOffDelay | Phase::Idle => {
                    on_event(GalvoEvent::Done { seq: a.seq });
                    self.active = None;
                    continue;
                }
            }
            self.active = Some(a);
        }
    }

    /// Plans and queues the jump to `point`.
    fn start(&mut self, point: Point, on_event: &mut impl FnMut(GalvoEvent)) {
        let target_rad = match self.angles_for(point.target_mm) {
            Ok(angles) => angles,
            Err(error) => {
                on_event(GalvoEvent::Refused {
                    seq: point.seq,
                    error,
                });
                return;
            }
        };
        let capacity = self
            .mirrors
            .x
            .free_samples()
            .min(self.mirrors.y.free_samples());
        let planned = plan_xy_jump(
            &self.disc,
            &self.disc,
            self.mirrors.end_position_rad(),
            target_rad,
            self.config.method,
            JumpSync::Independent,
            capacity,
        )
        .and_then(|jump| self.mirrors.queue_jump(&jump));
        match planned {
            Ok(()) => {
                self.active = Some(Active {
                    seq: point.seq,
                    phase: Phase::Jumping,
                    samples_left: 0,
                    dwell_samples: samples_for(point.dwell_us, self.config.sample_period_s),
                    cancelled: false,
                });
            }
            Err(_) => on_event(GalvoEvent::Refused {
                seq: point.seq,
                error: GalvoError::Planner,
            }),
        }
    }

    /// Latches an underrun: laser off, points dropped and refused until
    /// the next `Stop`.
    pub fn underrun(&mut self) {
        self.stop();
        self.faulted = true;
    }

    /// Runs the loop forever: requests between half buffers, one half per
    /// wake-up. An underrun turns the laser off, drops the queued points
    /// (also those still in the request channel) and is reported; points
    /// are refused until the next `Stop`.
    pub async fn run<D: DacStream>(&mut self, dac: &mut D, link: &GalvoLink) -> ! {
        let n = dac.half_len().clamp(1, MAX_HALF_LEN);
        let mut half = [DacSample::default(); MAX_HALF_LEN];
        let mut period_s = self.config.sample_period_s;
        dac.set_sample_period(period_s);
        loop {
            while let Ok(request) = link.requests.try_receive() {
                if let Some(event) = self.request(request) {
                    let _ = link.events.try_send(event);
                }
            }
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
            let out = &mut half[..n];
            self.fill(out, |event| {
                let _ = link.events.try_send(event);
            });
            link.halves.fetch_add(1, Ordering::Relaxed);
            link.publish(self.phase(), self.queue.len());
            if let Err(underrun) = dac.write_half(out).await {
                link.underruns.fetch_add(underrun.halves, Ordering::Relaxed);
                log::warning!(
                    "galvo: underrun ({} halves late), laser off",
                    underrun.halves
                );
                self.underrun();
                while let Ok(request) = link.requests.try_receive() {
                    if let Some(event) = self.request(request) {
                        let _ = link.events.try_send(event);
                    }
                }
                let _ = link.events.try_send(GalvoEvent::Underrun(underrun));
            }
        }
    }
}

impl Active {
    fn enter(&mut self, phase: Phase, samples: u32) {
        self.phase = phase;
        self.samples_left = samples;
    }
}

#[cfg(test)]
mod tests;
