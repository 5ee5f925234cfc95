//! The servo-bus set-up jobs ([`BusJob`], console `servo …`): scan the
//! bus, ping one id, give the one servo on the bus a new id, read an
//! angle. Each reports its findings as [`BusReport`] lines while it runs
//! and returns how it ended ([`BusEnd`]).
//!
//! FashionStar servos ship with the same id, and two servos with one id
//! answer together: their frames collide on the line and arrive garbled
//! (bad checksum), or — when their answers happen to be identical, as a
//! ping's are — the ping passes but the monitor query, whose answers
//! differ, does not. Either way the id is reported as a collision.

use core::sync::atomic::Ordering;

use embassy_time::{Duration, Instant, Timer, with_deadline};
use embedded_io_async::{Read, Write};
use fashionstar::{MAX_SERVO_ID, Request, Response};

use super::{BusEnd, BusJob, BusReport, ServoBus, ServoLink, ServoOutcome, ServoReading};

/// How long a scan waits for each id's ping answer (a servo answers
/// within about 1 ms at 115200 baud), so a scan of all 255 ids takes
/// about 2.6 s.
pub const SCAN_TIMEOUT: Duration = Duration::from_millis(10);
/// Pause after writing a new id before the servo is asked to answer as
/// it (the servo stores the id).
pub const ID_WRITE_SETTLE: Duration = Duration::from_millis(100);

/// What one request heard back.
enum Heard {
    Answer,
    /// Only frames that failed to decode (a collision).
    Garbled,
    Silent,
}

/// What pinging one id found.
enum Probe {
    Found(ServoReading),
    Collision,
    Silent,
    BusError,
}

/// What a scan of the whole bus found.
#[derive(Clone, Copy)]
struct Census {
    answering: u8,
    collisions: u8,
    /// The last id that answered cleanly.
    last: Option<u8>,
}

impl<R: Read, W: Write> ServoBus<R, W> {
    /// Runs set-up job `job` (request `seq`), reporting lines on `link`.
    pub(super) async fn setup(&mut self, seq: u32, job: BusJob, link: &ServoLink) -> BusEnd {
        match job {
            BusJob::Scan => match self.scan(seq, link).await {
                Ok(c) => BusEnd::Scanned {
                    answering: c.answering,
                    collisions: c.collisions,
                },
                Err(end) => end,
            },
            BusJob::Ping { id } => {
                let attempts = self.config.retries.saturating_add(1);
                match self.probe(id, attempts, self.timeout()).await {
                    Probe::Found(reading) => {
                        report(link, seq, BusReport::Servo(reading)).await;
                        BusEnd::Answered
                    }
                    Probe::Collision => {
                        report(link, seq, BusReport::Collision { id }).await;
                        BusEnd::NoAnswer { id }
                    }
                    Probe::Silent => BusEnd::NoAnswer { id },
                    Probe::BusError => BusEnd::BusError,
                }
            }
            BusJob::SetId { id, new_id } => self.set_id(seq, id, new_id, link).await,
            BusJob::ReadAngle { id } => match self.query_angle(id).await {
                Ok(tenths) => BusEnd::Angle { id, tenths },
                Err(_) => BusEnd::NoAnswer { id },
            },
        }
    }

    fn timeout(&self) -> Duration {
        Duration::from_millis(u64::from(self.config.response_timeout_ms))
    }

    /// Pings every id 0–254 once ([`SCAN_TIMEOUT`] each), reporting each
    /// servo found and each collision.
    async fn scan(&mut self, seq: u32, link: &ServoLink) -> Result<Census, BusEnd> {
        let mut census = Census {
            answering: 0,
            collisions: 0,
            last: None,
        };
        for id in 0..=MAX_SERVO_ID {
            link.alive.fetch_add(1, Ordering::Relaxed);
            match self.probe(id, 1, SCAN_TIMEOUT).await {
                Probe::Found(reading) => {
                    census.answering = census.answering.saturating_add(1);
                    census.last = Some(id);
                    report(link, seq, BusReport::Servo(reading)).await;
                }
                Probe::Collision => {
                    census.collisions = census.collisions.saturating_add(1);
                    report(link, seq, BusReport::Collision { id }).await;
                }
                Probe::Silent => {}
                Probe::BusError => return Err(BusEnd::BusError),
            }
        }
        Ok(census)
    }

    /// Gives servo `id` the id `new_id`: only when a scan finds it alone
    /// on the bus; the write's answer is checked, then the servo must
    /// answer a ping as `new_id`.
    async fn set_id(&mut self, seq: u32, id: u8, new_id: u8, link: &ServoLink) -> BusEnd {
        let census = match self.scan(seq, link).await {
            Ok(census) => census,
            Err(end) => return end,
        };
        match census {
            Census {
                answering: 1,
                collisions: 0,
                last: Some(only),
            } if only == id => {}
            Census {
                answering: 0 | 1,
                collisions: 0,
                ..
            } => return BusEnd::NoAnswer { id },
            Census {
                answering,
                collisions,
                ..
            } => {
                return BusEnd::NotAlone {
                    answering,
                    collisions,
                };
            }
        }
        // A servo may store the id before it answers, or answer as the
        // new id: what counts is that it answers as `new_id` afterwards.
        let refused = matches!(
            self.transact(Request::set_servo_id(id, new_id), id).await,
            Ok(Response::WriteData(w)) if !w.succeeded()
        );
        if refused {
            return BusEnd::WriteFailed { id };
        }
        Timer::after(ID_WRITE_SETTLE).await;
        let attempts = self.config.retries.saturating_add(1);
        match self.probe(new_id, attempts, self.timeout()).await {
            Probe::Found(reading) => {
                report(link, seq, BusReport::Servo(reading)).await;
                BusEnd::IdChanged { id, new_id }
            }
            Probe::BusError => BusEnd::BusError,
            Probe::Collision | Probe::Silent => BusEnd::WriteFailed { id },
        }
    }

    /// Pings `id` up to `attempts` times; when it answers, reads its
    /// monitor data.
    async fn probe(&mut self, id: u8, attempts: u8, timeout: Duration) -> Probe {
        let ping = Request::Ping { id };
        let mut garbled = false;
        let mut answered = false;
        for _ in 0..attempts {
            if self.send(&ping).await.is_err() {
                return Probe::BusError;
            }
            match self.listen(&ping, id, timeout).await {
                Heard::Answer => {
                    answered = true;
                    break;
                }
                Heard::Garbled => garbled = true,
                Heard::Silent => {}
            }
        }
        if !answered {
            return if garbled {
                Probe::Collision
            } else {
                Probe::Silent
            };
        }
        match self.transact(Request::QueryMonitor { id }, id).await {
            Ok(Response::Monitor(m)) => Probe::Found(ServoReading {
                id,
                angle_tenths: m.angle_tenths_deg,
                voltage_mv: m.voltage_mv,
                temperature_raw: m.temperature_raw,
            }),
            // It answers the ping (identical answers pass a collision)
            // but not the monitor query (different answers do not).
            _ => Probe::Collision,
        }
    }

    /// Waits up to `timeout` for servo `id`'s answer to `request`, noting
    /// frames that failed to decode.
    async fn listen(&mut self, request: &Request, id: u8, timeout: Duration) -> Heard {
        self.decoder.reset();
        let mut garbled = false;
        let heard = with_deadline(Instant::now() + timeout, async {
            let mut chunk = [0u8; 16];
            loop {
                let n = self.rx.read(&mut chunk).await.ok()?;
                for &byte in chunk.iter().take(n) {
                    match self.decoder.feed(byte) {
                        Some(Ok(response)) if response.id() == id && response.answers(request) => {
                            return Some(());
                        }
                        Some(Err(_)) => garbled = true,
                        _ => {}
                    }
                }
            }
        })
        .await;
        match heard {
            Ok(Some(())) => Heard::Answer,
            _ if garbled => Heard::Garbled,
            _ => Heard::Silent,
        }
    }
}

/// Sends one line of job `seq` to the sequencer.
async fn report(link: &ServoLink, seq: u32, report: BusReport) {
    link.outcomes.send(ServoOutcome::Bus { seq, report }).await;
}
