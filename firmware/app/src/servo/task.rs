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

//!
//! The types the task shares with the sequencer live in [`super::link`]
//! and [`super::id_set`]; they are re-exported here.

use core::sync::atomic::Ordering;

use embassy_time::{Duration, Instant, Timer, with_deadline, with_timeout};
use embedded_io_async::{Read, Write};
use fashionstar::{MAX_FRAME_LEN, Message, Request, Response, ResponseDecoder, SetAngle};

use super::plausibility::{IMPLAUSIBLE_RUN, ReadingFilter, Verdict};
use crate::log;

pub use super::id_set::ServoIdSet;
pub use super::link::{
    BusEnd, BusJob, BusReport, ServoBusConfig, ServoFault, ServoLink, ServoOutcome, ServoReading,
    ServoRequest,
};

mod setup;

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
            if matches!(request, ServoRequest::Move { .. }) {
                last_move = Some(request.seq());
            }
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
            ServoRequest::Setup { seq, job } => ServoOutcome::Bus {
                seq,
                report: BusReport::Done(self.setup(seq, job, link).await),
            },
            ServoRequest::Move {
                seq,
                yaw_tenths,
                pitch_tenths,
                interval_ms,
                ids: (yaw_id, pitch_id),
                deadband_tenths,
                ranges_tenths,
            } => {
                self.retarget((yaw_id, pitch_id), deadband_tenths, ranges_tenths);
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

    /// Takes the ids, deadband and ranges a move brings (from the
    /// settings) as the bus configuration from now on; a filter whose
    /// servo changed forgets its history.
    fn retarget(&mut self, (yaw_id, pitch_id): (u8, u8), deadband: u16, ranges: [(i16, i16); 2]) {
        self.config.yaw_id = yaw_id;
        self.config.pitch_id = pitch_id;
        self.config.deadband_tenths = deadband;
        self.config.ranges_tenths = ranges;
        for ((filter_id, filter), (id, range)) in self
            .filters
            .iter_mut()
            .zip([yaw_id, pitch_id].into_iter().zip(ranges))
        {
            if *filter_id != id {
                // Another servo: its history says nothing.
                *filter_id = id;
                filter.reset();
            }
            filter.set_range(range);
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
