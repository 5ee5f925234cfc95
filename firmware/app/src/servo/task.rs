//! The servo task body: owns the servo UART, turns [`ServoRequest`]s into
//! FashionStar frames, waits for responses with a timeout and bounded
//! retries, detects arrival by polling the angles, and reports a
//! [`ServoOutcome`] for every request. A servo that stops answering is a
//! fault; it is pinged while idle and reported again when it recovers.
//!
//! Every angle reading passes the plausibility filter of
//! [`super::plausibility`] before it can drive arrival or fault logic: a
//! reading outside the servo's range, or a jump no servo can make, is
//! rejected and counted ([`ServoLink::implausible_readings`]), and a run of
//! them is a fault ([`ServoFault::ImplausibleReading`]). Arrival is
//! declared only when two readings in a row (the second taken at once to
//! confirm the first) are inside the deadband.

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::{Duration, Instant, Timer, with_deadline, with_timeout};
use embedded_io_async::{Read, Write};

use super::plausibility::{IMPLAUSIBLE_RUN, ReadingFilter, Verdict, WIRE_LIMIT_TENTHS};
use crate::log;
use fashionstar::{MAX_FRAME_LEN, Message, Request, Response, ResponseDecoder, SetAngle};

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
    /// Configured angle range of the yaw and the pitch servo, 0.1°
    /// (`(min, max)`; readings outside are implausible).
    pub ranges_tenths: [(i16, i16); 2],
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
            ranges_tenths: [(-WIRE, WIRE); 2],
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
        /// Configured range `(min, max)` of the yaw and the pitch servo,
        /// 0.1° (used from now on by the plausibility filter).
        ranges_tenths: [(i16, i16); 2],
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
    /// [`IMPLAUSIBLE_RUN`] angle readings in a row were physically
    /// impossible (outside the range, or a jump no servo can make): the
    /// bus delivers corrupted frames that pass the checksum.
    ImplausibleReading {
        /// The last rejected reading, 0.1°.
        at_tenths: i16,
    },
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
    /// Angle readings rejected as physically impossible since boot.
    pub implausible_readings: AtomicU32,
}

impl ServoLink {
    /// Empty channels (usable in a `static`).
    pub const fn new() -> Self {
        Self {
            requests: Channel::new(),
            outcomes: Channel::new(),
            alive: AtomicU32::new(0),
            implausible_readings: AtomicU32::new(0),
        }
    }
}

impl Default for ServoLink {
    fn default() -> Self {
        Self::new()
    }
}

/// Largest single-turn angle, 0.1° (default range before the first move).
const WIRE: i16 = WIRE_LIMIT_TENTHS as i16;

/// A set of servo bus ids (0..=255), e.g. the servos known faulty.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ServoIdSet([u32; 8]);

impl ServoIdSet {
    /// The empty set.
    pub const fn new() -> Self {
        Self([0; 8])
    }

    fn word_bit(id: u8) -> (usize, u32) {
        (usize::from(id / 32), 1u32 << (id % 32))
    }

    /// Adds `id`.
    pub fn insert(&mut self, id: u8) {
        let (w, bit) = Self::word_bit(id);
        if let Some(word) = self.0.get_mut(w) {
            *word |= bit;
        }
    }

    /// Removes `id`.
    pub fn remove(&mut self, id: u8) {
        let (w, bit) = Self::word_bit(id);
        if let Some(word) = self.0.get_mut(w) {
            *word &= !bit;
        }
    }

    /// Whether `id` is in the set.
    pub fn contains(&self, id: u8) -> bool {
        let (w, bit) = Self::word_bit(id);
        self.0.get(w).is_some_and(|word| word & bit != 0)
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.0.iter().all(|w| *w == 0)
    }

    /// The smallest id in the set.
    pub fn first(&self) -> Option<u8> {
        self.iter().next()
    }

    /// The ids in the set, ascending.
    pub fn iter(&self) -> impl Iterator<Item = u8> + '_ {
        (0..=u8::MAX).filter(|id| self.contains(*id))
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
    /// Servos known faulty (pinged until they answer again).
    faulty: ServoIdSet,
    /// Plausibility filter of the yaw and the pitch servo's readings, with
    /// the id each belongs to.
    filters: [(u8, ReadingFilter); 2],
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
            faulty: ServoIdSet::new(),
            filters: [
                (config.yaw_id, ReadingFilter::new(config.ranges_tenths[0])),
                (config.pitch_id, ReadingFilter::new(config.ranges_tenths[1])),
            ],
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
                    if !self.faulty.is_empty() && now >= next_recovery_ping {
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
                    self.faulty.insert(id);
                }
                ServoOutcome::Arrived { .. } => {
                    self.faulty.remove(self.config.yaw_id);
                    self.faulty.remove(self.config.pitch_id);
                }
                _ => {}
            }
            link.outcomes.send(outcome).await;
        }
    }

    /// Queries the angle of every servo not yet known faulty; one that does
    /// not answer is reported as a fault of move `seq`.
    async fn health_check(&mut self, link: &ServoLink, seq: u32) {
        for (slot, id) in [(0, self.config.yaw_id), (1, self.config.pitch_id)] {
            if self.faulty.contains(id) {
                continue;
            }
            // A rejected reading (`Ok(None)`) is no news; a run of them is.
            if let Err(fault) = self.read_angle(slot, id, link).await {
                log::warning!("servo {}: fault {:?} while holding", id, fault);
                self.faulty.insert(id);
                link.outcomes
                    .send(ServoOutcome::Fault { seq, id, fault })
                    .await;
            }
        }
    }

    /// Pings every servo known faulty (also one no longer configured, so
    /// whoever marked it learns when it answers again).
    async fn ping_faulty(&mut self, link: &ServoLink) {
        let faulty = self.faulty;
        for id in faulty.iter() {
            if matches!(
                self.transact(Request::Ping { id }, id).await,
                Ok(Response::Ping { .. })
            ) {
                log::info!("servo {}: answering again", id);
                self.faulty.remove(id);
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
                ranges_tenths,
            } => {
                self.config.yaw_id = yaw_id;
                self.config.pitch_id = pitch_id;
                self.config.deadband_tenths = deadband_tenths;
                self.config.ranges_tenths = ranges_tenths;
                for ((filter_id, filter), (id, range)) in self
                    .filters
                    .iter_mut()
                    .zip([yaw_id, pitch_id].into_iter().zip(ranges_tenths))
                {
                    if *filter_id != id {
                        // Another servo: its history says nothing.
                        *filter_id = id;
                        filter.reset();
                    }
                    filter.set_range(range);
                }
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

    /// Polls both angles until both are within the deadband (confirmed by
    /// a second reading at once), the deadline passes, or a newer request
    /// is waiting. Implausible readings never count as arrived.
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
        let off = |angle: i16, target: i16| (i32::from(angle) - i32::from(target)).abs();
        loop {
            let (yaw, pitch) = match self.read_both(link).await {
                Ok(readings) => readings,
                Err(fault) => return fault,
            };
            let inside = |yaw: Option<i16>, pitch: Option<i16>| {
                yaw.is_some_and(|a| off(a, yaw_target) <= deadband)
                    && pitch.is_some_and(|a| off(a, pitch_target) <= deadband)
            };
            if inside(yaw, pitch) {
                // Confirm with a second reading of both before declaring.
                match self.read_both(link).await {
                    Ok((Some(yaw), Some(pitch))) if inside(Some(yaw), Some(pitch)) => {
                        return Poll::Arrived(yaw, pitch);
                    }
                    Ok(_) => {}
                    Err(fault) => return fault,
                }
            }
            if Instant::now() >= deadline {
                // The last believed angles (a rejected reading is no
                // evidence either way).
                let believed = |slot: usize| self.filters.get(slot).and_then(|f| f.1.last_good());
                let yaw = yaw.or(believed(0));
                let pitch = pitch.or(believed(1));
                let yaw_away = yaw.is_none_or(|a| off(a, yaw_target) > deadband);
                let (id, at, target) = if yaw_away {
                    (self.config.yaw_id, yaw, yaw_target)
                } else {
                    (self.config.pitch_id, pitch, pitch_target)
                };
                return Poll::Fault(
                    id,
                    ServoFault::NotArrived {
                        at_tenths: at.unwrap_or(i16::MIN),
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

    /// Reads yaw then pitch; `None` for a reading the filter rejected.
    async fn read_both(&mut self, link: &ServoLink) -> Result<(Option<i16>, Option<i16>), Poll> {
        let (yaw_id, pitch_id) = (self.config.yaw_id, self.config.pitch_id);
        let yaw = self
            .read_angle(0, yaw_id, link)
            .await
            .map_err(|fault| Poll::Fault(yaw_id, fault))?;
        let pitch = self
            .read_angle(1, pitch_id, link)
            .await
            .map_err(|fault| Poll::Fault(pitch_id, fault))?;
        Ok((yaw, pitch))
    }

    /// Queries the angle of servo `id` (filter `slot`: 0 yaw, 1 pitch) and
    /// judges it: `Ok(Some(angle))` when plausible, `Ok(None)` when
    /// rejected (counted), `Err` when the servo does not answer or
    /// [`IMPLAUSIBLE_RUN`] readings in a row were implausible.
    async fn read_angle(
        &mut self,
        slot: usize,
        id: u8,
        link: &ServoLink,
    ) -> Result<Option<i16>, ServoFault> {
        let reading = self.query_angle(id).await?;
        let now = Instant::now();
        let Some((_, filter)) = self.filters.get_mut(slot) else {
            return Ok(Some(reading));
        };
        match filter.judge(reading, now) {
            Verdict::Accepted(angle) => Ok(Some(angle)),
            Verdict::Unconfirmed => Ok(None),
            Verdict::Implausible { run } => {
                link.implausible_readings.fetch_add(1, Ordering::Relaxed);
                log::warning!(
                    "servo {}: implausible reading {} (0.1 deg), {} in a row",
                    id,
                    reading,
                    run
                );
                if run >= IMPLAUSIBLE_RUN {
                    filter.reset();
                    Err(ServoFault::ImplausibleReading { at_tenths: reading })
                } else {
                    Ok(None)
                }
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
