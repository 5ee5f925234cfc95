//! The simulated servo UART: the firmware's servo task writes real request
//! bytes here and reads real response bytes, with 115200-baud wire timing,
//! delivered by the simulated FashionStar servos of [`crate::servo_model`].
//! Fault injection (silent servo, corrupted bytes, slow servos) happens on
//! this path.

use std::cell::RefCell;
use std::collections::VecDeque;
use std::convert::Infallible;
use std::rc::Rc;

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::{Instant, Timer};

use crate::recorder::{CorruptedFrame, Direction, FrameRecord, Recording};
use crate::servo_model::SimServoBus;

/// Time one byte takes on the wire at 115200 baud 8N1 (10 bits), µs.
pub const BYTE_TIME_US: u64 = 87;

/// Injected servo-bus faults.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BusFaults {
    /// Servos that stop answering for a while.
    pub silent: Vec<SilentWindow>,
    /// Probability that a response byte is corrupted (one bit flipped).
    pub corrupt_probability: f64,
    /// Probability that an angle response is corrupted so that its 8-bit
    /// checksum still holds (two bit flips that cancel in the sum, as
    /// random corruption produces now and then): a wrong angle the
    /// checksum cannot catch.
    pub forge_probability: f64,
    /// Seed of the corruption's random numbers (0: the default seed).
    pub seed: u64,
}

/// Servo `id` does not answer from `from_ms` until `until_ms` (for good
/// when `None`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SilentWindow {
    /// Bus id.
    pub id: u8,
    /// Start of the silence, simulated ms.
    pub from_ms: u64,
    /// End of the silence, simulated ms.
    pub until_ms: Option<u64>,
}

impl SilentWindow {
    /// Whether the servo is silent at `t_us`.
    pub fn covers(&self, t_us: u64) -> bool {
        t_us >= self.from_ms * 1000 && self.until_ms.is_none_or(|end| t_us < end * 1000)
    }
}

/// What the injected faults do to the bus: silences by time, and damaged
/// response bytes (flipped bits, forged angles) drawn from a seeded
/// generator. Shared by the simulated UART ([`SimServoPort`]) and the
/// servo bus `cargo xtask qemu` serves to the emulated board.
#[derive(Debug, Clone)]
pub struct FaultInjector {
    faults: BusFaults,
    rng: u64,
}

impl FaultInjector {
    /// The effect of `faults`, with random numbers from `seed` (unless the
    /// faults name their own seed).
    pub fn new(faults: BusFaults, seed: u64) -> Self {
        let rng_seed = if faults.seed != 0 { faults.seed } else { seed };
        Self {
            faults,
            rng: rng_seed | 1,
        }
    }

    fn random_unit(&mut self) -> f64 {
        let x = &mut self.rng;
        *x ^= *x << 13;
        *x ^= *x >> 7;
        *x ^= *x << 17;
        (*x >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Silences (or lets answer again) each servo a silence window names,
    /// as the windows say for `now_us`.
    pub fn apply_silence(&self, bus: &mut SimServoBus, now_us: u64) {
        for window in &self.faults.silent {
            let silent = self
                .faults
                .silent
                .iter()
                .any(|w| w.id == window.id && w.covers(now_us));
            bus.set_silent(window.id, silent);
        }
    }

    /// Damages `response` as the faults say: maybe a forged angle (valid
    /// checksum), then maybe flipped bits in each byte.
    pub fn damage(&mut self, response: &mut [u8]) {
        if self.faults.forge_probability > 0.0 && self.random_unit() < self.faults.forge_probability
        {
            self.forge_angle(response);
        }
        for byte in response.iter_mut() {
            if self.faults.corrupt_probability > 0.0
                && self.random_unit() < self.faults.corrupt_probability
            {
                *byte ^= 1 << (self.random_unit() * 8.0) as u32;
            }
        }
    }

    /// Flips two bits of an angle response (code 10, 8 bytes) so that the
    /// checksum still holds: the same bit set in one angle byte and cleared
    /// in the other, or set in an angle byte and in the checksum.
    fn forge_angle(&mut self, frame: &mut [u8]) {
        const ANGLE_CODE: u8 = 10;
        if frame.len() != 8 || frame.get(2) != Some(&ANGLE_CODE) {
            return;
        }
        let (lo, hi, cs) = (5, 6, 7);
        for _ in 0..32 {
            let mask = 1u8 << (self.random_unit() * 8.0) as u32;
            let (a, b) = if self.random_unit() < 0.5 {
                (lo, hi)
            } else {
                (hi, lo)
            };
            if self.random_unit() < 0.5 {
                if frame[a] & mask == 0 && frame[b] & mask != 0 {
                    frame[a] |= mask;
                    frame[b] &= !mask;
                    return;
                }
            } else if frame[a] & mask == 0 && frame[cs] & mask == 0 {
                frame[a] |= mask;
                frame[cs] |= mask;
                return;
            }
        }
    }
}

/// The bus seen from the firmware: write requests, read responses.
pub struct SimServoPort {
    bus: Rc<RefCell<SimServoBus>>,
    recording: Rc<RefCell<Recording>>,
    injector: RefCell<FaultInjector>,
    /// Response bytes with the time each becomes readable, µs.
    incoming: RefCell<VecDeque<(u64, u8)>>,
    arrived: Signal<CriticalSectionRawMutex, ()>,
}

impl SimServoPort {
    /// A port on `bus`, recording frames into `recording`.
    pub fn new(
        bus: Rc<RefCell<SimServoBus>>,
        recording: Rc<RefCell<Recording>>,
        faults: BusFaults,
        seed: u64,
    ) -> Self {
        Self {
            bus,
            recording,
            injector: RefCell::new(FaultInjector::new(faults, seed)),
            incoming: RefCell::default(),
            arrived: Signal::new(),
        }
    }

    /// Records a frame sent from `start` to `done` (µs), lets the servos
    /// act on it and queues their responses.
    fn deliver(&self, start: u64, done: u64, bytes: &[u8]) {
        self.recording.borrow_mut().frames.push(FrameRecord {
            t_us: start,
            direction: Direction::Tx,
            bytes: bytes.to_vec(),
        });
        let mut injector = self.injector.borrow_mut();
        injector.apply_silence(&mut self.bus.borrow_mut(), done);
        let responses = self.bus.borrow_mut().receive(done, bytes);
        for (ready_at_us, mut response) in responses {
            let sent = response.clone();
            injector.damage(&mut response);
            let mut recording = self.recording.borrow_mut();
            if response != sent {
                recording.clean_rx.push(CorruptedFrame {
                    t_us: ready_at_us,
                    sent,
                    received: response.clone(),
                });
            }
            recording.frames.push(FrameRecord {
                t_us: ready_at_us,
                direction: Direction::Rx,
                bytes: response.clone(),
            });
            drop(recording);
            let mut incoming = self.incoming.borrow_mut();
            for (i, byte) in response.into_iter().enumerate() {
                incoming.push_back((ready_at_us + BYTE_TIME_US * (i as u64 + 1), byte));
            }
        }
    }

    async fn write_bytes(&self, bytes: &[u8]) {
        let start = Instant::now().as_micros();
        // The bytes are on the wire for their transmission time.
        Timer::after_micros(BYTE_TIME_US * bytes.len() as u64).await;
        let done = Instant::now().as_micros();
        // The simulated bus and servos: not firmware work.
        crate::executor::simulator_work(|| self.deliver(start, done, bytes));
        self.arrived.signal(());
    }

    async fn read_bytes(&self, buf: &mut [u8]) -> usize {
        loop {
            let now = Instant::now().as_micros();
            let next = self.incoming.borrow().front().map(|(t, _)| *t);
            match next {
                Some(t) if t <= now => {
                    let mut incoming = self.incoming.borrow_mut();
                    let mut n = 0;
                    while n < buf.len() {
                        match incoming.front() {
                            Some(&(t, byte)) if t <= now => {
                                buf[n] = byte;
                                n += 1;
                                incoming.pop_front();
                            }
                            _ => break,
                        }
                    }
                    return n;
                }
                Some(t) => Timer::at(Instant::from_micros(t)).await,
                None => self.arrived.wait().await,
            }
        }
    }
}

/// Firmware-side handle implementing `embedded_io_async::{Read, Write}`.
#[derive(Clone)]
pub struct PortHandle(pub Rc<SimServoPort>);

impl embedded_io_async::ErrorType for PortHandle {
    type Error = Infallible;
}

impl embedded_io_async::Write for PortHandle {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        self.0.write_bytes(buf).await;
        Ok(buf.len())
    }

    /// `write` returns once its bytes have left the wire, so there is
    /// never anything buffered to flush.
    async fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

impl embedded_io_async::Read for PortHandle {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        Ok(self.0.read_bytes(buf).await)
    }
}
