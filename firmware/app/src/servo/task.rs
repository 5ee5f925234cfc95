//! The servo task body: owns the servo UART, turns [`ServoRequest`]s into
//! FashionStar frames, waits for responses with a timeout and bounded
//! retries, detects arrival by polling the angles, and reports a
//! [`ServoOutcome`] for every request. A servo that stops answering is a
//! fault; it is pinged while idle and reported again when it recovers.

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::{Duration, Instant, Timer, with_deadline, with_timeout};
use embedded_io_async::{Read, Write};

use super::protocol::{MAX_FRAME_LEN, Request, Response, ResponseDecoder, SetAngle};
use crate::log;

/// Servo ids and timing of the servo bus. All durations in ms, angles in
/// the servo's wire unit (0.1°).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServoBusConfig {
    /// Bus id of the yaw servo.
    pub yaw_id: u8,
    /// Bus id of the pitch servo.
    pub pitch_id: u8,
    /// Arrived when both measured angles are within this many 0.1° steps.
    pub deadband_tenths: u16,
    /// How long to wait for a response frame, ms.
    pub response_timeout_ms: u16,
    /// Extra attempts after a query got no valid response.
    pub retries: u8,
    /// Period of angle polls while waiting for arrival, ms.
    pub poll_period_ms: u16,
    /// Arrival deadline beyond the commanded interval, ms (plus 50 % of
    /// the interval); a move not finished by then is a fault.
    pub arrival_margin_ms: u16,
    /// Period of the health check while no move runs (both angles are
    /// queried, so a servo that stops answering during a dwell or a held
    /// goto is a fault within this period plus the retries), ms.
    pub health_check_ms: u16,
}

impl Default for ServoBusConfig {
    fn default() -> Self {
        Self {
            yaw_id: 0,
            pitch_id: 1,
            deadband_tenths: 5,
            response_timeout_ms: 20,
            retries: 2,
            poll_period_ms: 10,
            arrival_margin_ms: 300,
            health_check_ms: 100,
        }
    }
}

/// What the sequencer asks of the servo task. `seq` ties the outcome to
/// the request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoRequest {
    /// Start both servos towards the given wire angles (0.1°) together,
    /// taking `interval_ms`, and report when both have arrived.
    Move {
        /// Request number.
        seq: u32,
        /// Yaw servo target, 0.1°.
        yaw_tenths: i16,
        /// Pitch servo target, 0.1°.
        pitch_tenths: i16,
        /// Commanded travel time, ms.
        interval_ms: u16,
        /// Bus ids `(yaw, pitch)` (from the settings; used from now on).
        ids: (u8, u8),
        /// Arrival deadband, 0.1° (used from now on).
        deadband_tenths: u16,
    },
}

impl ServoRequest {
    /// The request number.
    pub fn seq(&self) -> u32 {
        match self {
            ServoRequest::Move { seq, .. } => *seq,
        }
    }
}

/// Why a servo is considered faulty.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoFault {
    /// No valid response after all retries.
    NoResponse,
    /// Still away from the target at the arrival deadline (measured angle,
    /// 0.1°).
    NotArrived {
        /// Last measured angle, 0.1°.
        at_tenths: i16,
        /// Target angle, 0.1°.
        target_tenths: i16,
    },
    /// Writing to the UART failed.
    BusError,
}

/// What the servo task reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoOutcome {
    /// Both servos are within the deadband of the targets of `Move` `seq`.
    Arrived {
        /// Request number.
        seq: u32,
        /// Measured yaw angle, 0.1°.
        yaw_tenths: i16,
        /// Measured pitch angle, 0.1°.
        pitch_tenths: i16,
    },
    /// Request `seq` failed because servo `id` is faulty.
    Fault {
        /// Request number.
        seq: u32,
        /// Bus id of the faulty servo.
        id: u8,
        /// What went wrong.
        fault: ServoFault,
    },
    /// Request `seq` was abandoned because a newer request arrived.
    Superseded {
        /// Request number.
        seq: u32,
    },
    /// A previously faulty servo answers again (found while idle).
    Recovered {
        /// Bus id.
        id: u8,
    },
}

/// Channels between the sequencer and the servo task.
pub struct ServoLink {
    /// Sequencer → servo task.
    pub requests: Channel<CriticalSectionRawMutex, ServoRequest, 1>,
    /// Servo task → sequencer.
    pub outcomes: Channel<CriticalSectionRawMutex, ServoOutcome, 4>,
    /// Incremented by the servo task at least every [`IDLE_TICK`]
    /// (liveness for the watchdog).
    pub alive: AtomicU32,
}

impl ServoLink {
    /// Empty channels (usable in a `static`).
    pub const fn new() -> Self {
        Self {
            requests: Channel::new(),
            outcomes: Channel::new(),
            alive: AtomicU32::new(0),
        }
    }
}

impl Default for ServoLink {
    fn default() -> Self {
        Self::new()
    }
}

/// Power limit sent with every move, mW (0 = the servo's own limit).
const POWER_MW: u16 = 0;
/// How often faulty servos are pinged while idle.
const RECOVERY_PING_PERIOD: Duration = Duration::from_millis(500);
/// Longest the task waits for a request before showing it is alive.
pub const IDLE_TICK: Duration = Duration::from_millis(250);

/// The servo bus: UART halves, decoder and fault bookkeeping.
pub struct ServoBus<R, W> {
    rx: R,
    tx: W,
    decoder: ResponseDecoder,
    config: ServoBusConfig,
    /// Faulty flags for yaw and pitch.
    faulty: [bool; 2],
}

enum Poll {
    Arrived(i16, i16),
    Fault(u8, ServoFault),
    Superseded,
}

impl<R: Read, W: Write> ServoBus<R, W> {
    /// A bus on the given UART halves.
    pub fn new(rx: R, tx: W, config: ServoBusConfig) -> Self {
        Self {
            rx,
            tx,
            decoder: ResponseDecoder::new(),
            config,
            faulty: [false; 2],
        }
    }

    /// Serves requests forever. Between requests it checks the servos'
    /// health (answering servos) and pings faulty ones for recovery.
    pub async fn run(&mut self, link: &ServoLink) -> ! {
        let mut next_recovery_ping = Instant::now() + RECOVERY_PING_PERIOD;
        let health_period = Duration::from_millis(u64::from(self.config.health_check_ms.max(1)));
        let mut next_health_check = Instant::now() + health_period;
        // Request number of the last move (faults found by the health check
        // belong to it).
        let mut last_move: Option<u32> = None;
        loop {
            link.alive.fetch_add(1, Ordering::Relaxed);
            let wake = next_health_check.min(Instant::now() + IDLE_TICK);
            let request = match with_deadline(wake, link.requests.receive()).await {
                Ok(request) => request,
                Err(_) => {
                    let now = Instant::now();
                    // Only after a move: ids and deadband come with moves
                    // (from the settings), so before the first one this
                    // task does not know which servos to expect.
                    if now >= next_health_check {
                        next_health_check = now + health_period;
                        if let Some(seq) = last_move {
                            self.health_check(link, seq).await;
                        }
                    }
                    if self.faulty.iter().any(|f| *f) && now >= next_recovery_ping {
                        next_recovery_ping = now + RECOVERY_PING_PERIOD;
                        self.ping_faulty(link).await;
                    }
                    continue;
                }
            };
            last_move = Some(request.seq());
            next_health_check = Instant::now() + health_period;
            let outcome = self.serve(request, link).await;
            match outcome {
                ServoOutcome::Fault { id, fault, .. } => {
                    log::warning!("servo {}: fault {:?}", id, fault);
                    self.set_faulty(id, true);
                }
                ServoOutcome::Arrived { .. } => {
                    self.faulty = [false; 2];
                }
                _ => {}
            }
            link.outcomes.send(outcome).await;
        }
    }

    fn set_faulty(&mut self, id: u8, faulty: bool) {
        if id == self.config.yaw_id {
            self.faulty[0] = faulty;
        }
        if id == self.config.pitch_id {
            self.faulty[1] = faulty;
        }
    }

    /// Queries the angle of every servo not yet known faulty; one that does
    /// not answer is reported as a fault of move `seq`.
    async fn health_check(&mut self, link: &ServoLink, seq: u32) {
        for (slot, id) in [(0, self.config.yaw_id), (1, self.config.pitch_id)] {
            if self.faulty.get(slot).copied().unwrap_or(true) {
                continue;
            }
            if let Err(fault) = self.query_angle(id).await {
                log::warning!("servo {}: fault {:?} while holding", id, fault);
                self.set_faulty(id, true);
                link.outcomes
                    .send(ServoOutcome::Fault { seq, id, fault })
                    .await;
            }
        }
    }

    async fn ping_faulty(&mut self, link: &ServoLink) {
        for (slot, id) in [(0, self.config.yaw_id), (1, self.config.pitch_id)] {
            if self.faulty.get(slot).copied().unwrap_or(false)
                && matches!(
                    self.transact(Request::Ping { id }, id).await,
                    Ok(Response::Ping { .. })
                )
            {
                log::info!("servo {}: answering again", id);
                self.set_faulty(id, false);
                link.outcomes.send(ServoOutcome::Recovered { id }).await;
            }
        }
    }

    async fn serve(&mut self, request: ServoRequest, link: &ServoLink) -> ServoOutcome {
        match request {
            ServoRequest::Move {
                seq,
                yaw_tenths,
                pitch_tenths,
                interval_ms,
                ids: (yaw_id, pitch_id),
                deadband_tenths,
            } => {
                if (yaw_id, pitch_id) != (self.config.yaw_id, self.config.pitch_id) {
                    self.faulty = [false; 2];
                }
                self.config.yaw_id = yaw_id;
                self.config.pitch_id = pitch_id;
                self.config.deadband_tenths = deadband_tenths;
                let entry = |id, angle_tenths_deg| SetAngle {
                    id,
                    angle_tenths_deg,
                    interval_ms,
                    power_mw: POWER_MW,
                };
                let start = Request::sync_set_angle_pair(
                    entry(self.config.yaw_id, yaw_tenths),
                    entry(self.config.pitch_id, pitch_tenths),
                );
                if self.send(&start).await.is_err() {
                    return ServoOutcome::Fault {
                        seq,
                        id: self.config.yaw_id,
                        fault: ServoFault::BusError,
                    };
                }
                match self
                    .wait_arrival(yaw_tenths, pitch_tenths, interval_ms, link)
                    .await
                {
                    Poll::Arrived(yaw, pitch) => ServoOutcome::Arrived {
                        seq,
                        yaw_tenths: yaw,
                        pitch_tenths: pitch,
                    },
                    Poll::Fault(id, fault) => ServoOutcome::Fault { seq, id, fault },
                    Poll::Superseded => ServoOutcome::Superseded { seq },
                }
            }
        }
    }

    /// Polls both angles until both are within the deadband, the deadline
    /// passes, or a newer request is waiting.
    async fn wait_arrival(
        &mut self,
        yaw_target: i16,
        pitch_target: i16,
        interval_ms: u16,
        link: &ServoLink,
    ) -> Poll {
        let interval = u64::from(interval_ms);
        let deadline = Instant::now()
            + Duration::from_millis(
                interval + interval / 2 + u64::from(self.config.arrival_margin_ms),
            );
        let deadband = i32::from(self.config.deadband_tenths);
        loop {
            let yaw = match self.query_angle(self.config.yaw_id).await {
                Ok(a) => a,
                Err(fault) => return Poll::Fault(self.config.yaw_id, fault),
            };
            let pitch = match self.query_angle(self.config.pitch_id).await {
                Ok(a) => a,
                Err(fault) => return Poll::Fault(self.config.pitch_id, fault),
            };
            let yaw_off = (i32::from(yaw) - i32::from(yaw_target)).abs();
            let pitch_off = (i32::from(pitch) - i32::from(pitch_target)).abs();
            if yaw_off <= deadband && pitch_off <= deadband {
                return Poll::Arrived(yaw, pitch);
            }
            if Instant::now() >= deadline {
                let (id, at, target) = if yaw_off > deadband {
                    (self.config.yaw_id, yaw, yaw_target)
                } else {
                    (self.config.pitch_id, pitch, pitch_target)
                };
                return Poll::Fault(
                    id,
                    ServoFault::NotArrived {
                        at_tenths: at,
                        target_tenths: target,
                    },
                );
            }
            if !link.requests.is_empty() {
                return Poll::Superseded;
            }
            link.alive.fetch_add(1, Ordering::Relaxed);
            Timer::after_millis(u64::from(self.config.poll_period_ms)).await;
            if !link.requests.is_empty() {
                return Poll::Superseded;
            }
        }
    }

    async fn query_angle(&mut self, id: u8) -> Result<i16, ServoFault> {
        match self.transact(Request::QueryAngle { id }, id).await? {
            Response::Angle {
                angle_tenths_deg, ..
            } => Ok(angle_tenths_deg),
            _ => Err(ServoFault::NoResponse),
        }
    }

    /// Sends `request` and waits for the matching response from servo `id`,
    /// retrying on timeout or corrupt frames.
    async fn transact(&mut self, request: Request, id: u8) -> Result<Response, ServoFault> {
        for attempt in 0..=self.config.retries {
            self.send(&request)
                .await
                .map_err(|_| ServoFault::BusError)?;
            let timeout = Duration::from_millis(u64::from(self.config.response_timeout_ms));
            if let Ok(Some(response)) = with_timeout(timeout, self.receive_from(id, &request)).await
            {
                return Ok(response);
            }
            log::debug!("servo {}: no valid response (attempt {})", id, attempt + 1);
        }
        Err(ServoFault::NoResponse)
    }

    async fn send(&mut self, request: &Request) -> Result<(), W::Error> {
        let mut frame = [0u8; MAX_FRAME_LEN];
        // Every request the task builds fits in MAX_FRAME_LEN.
        let len = request.encode(&mut frame).unwrap_or(0);
        self.tx.write_all(frame.get(..len).unwrap_or(&[])).await?;
        self.tx.flush().await
    }

    /// Reads until a response from `id` answering `request` arrives (other
    /// frames and garbage are skipped). `None` when the UART read fails.
    async fn receive_from(&mut self, id: u8, request: &Request) -> Option<Response> {
        let mut chunk = [0u8; 16];
        loop {
            let n = self.rx.read(&mut chunk).await.ok()?;
            for &byte in chunk.iter().take(n) {
                if let Some(Ok(response)) = self.decoder.feed(byte)
                    && response.id() == id
                    && response.answers(request)
                {
                    return Some(response);
                }
            }
        }
    }
}
