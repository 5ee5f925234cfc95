//! Several simulated servos on one half-duplex line: the request decoder
//! they share, the answers' wire timing and the log of every frame.

use fashionstar::{Message, Request, RequestDecoder};

use super::sim_servo::{PROCESSING_DELAY_US, SimServo, wire_time_us};

/// Direction of a frame on the servo bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BusDirection {
    /// Controller → servo (request).
    Tx,
    /// Servo → controller (response).
    Rx,
}

/// One complete frame seen on the bus.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BusFrame {
    /// When its first byte started on the wire, µs.
    pub t_us: u64,
    /// Direction.
    pub direction: BusDirection,
    /// The frame's bytes.
    pub bytes: Vec<u8>,
}

/// Several simulated servos sharing one half-duplex line, each on its own
/// cable (slot) that can be unplugged and plugged back.
///
/// Two servos with one id (FashionStar servos ship that way) both carry
/// out what is addressed to it and both answer at once: their answers
/// collide on the line. The model: the controller receives one frame, the
/// bytewise AND of the answers (an idle-high line: a 0 bit from either
/// wins) as long as the longest, with its checksum byte inverted — the two
/// never start in exact bit alignment, so the collision always fails the
/// checksum (even for identical answers, such as a ping's).
#[derive(Default)]
pub struct SimServoBus {
    servos: Vec<SimServo>,
    /// Slots whose cable is unplugged (their servos hear and say nothing).
    unplugged: Vec<bool>,
    decoder: RequestDecoder,
    /// The line is busy with responses until then, µs.
    line_free_at_us: u64,
    frames: Vec<BusFrame>,
    decode_errors: u64,
}

impl SimServoBus {
    /// Servos with the given ids at 0°, each with `slow_factor`.
    pub fn new(ids: &[u8], slow_factor: f64) -> Self {
        Self::from_servos(
            ids.iter()
                .map(|&id| {
                    let mut servo = SimServo::new(id);
                    servo.set_slow_factor(slow_factor);
                    servo
                })
                .collect(),
        )
    }

    /// A bus with these servos (slots 0, 1, … in this order).
    pub fn from_servos(servos: Vec<SimServo>) -> Self {
        Self {
            unplugged: vec![false; servos.len()],
            servos,
            ..Self::default()
        }
    }

    /// Unplugs (or plugs back) the cable of the servo in `slot` (0: the
    /// first servo given); `false` when there is no such slot.
    pub fn set_plugged(&mut self, slot: usize, plugged: bool) -> bool {
        match self.unplugged.get_mut(slot) {
            Some(unplugged) => {
                *unplugged = !plugged;
                true
            }
            None => false,
        }
    }

    /// The servo in `slot`.
    pub fn servo_in_slot(&self, slot: usize) -> Option<&SimServo> {
        self.servos.get(slot)
    }

    /// Servo `id`.
    pub fn servo(&self, id: u8) -> Option<&SimServo> {
        self.servos.iter().find(|s| s.id == id)
    }

    /// Servo `id`, mutable (fault injection, test setup).
    pub fn servo_mut(&mut self, id: u8) -> Option<&mut SimServo> {
        self.servos.iter_mut().find(|s| s.id == id)
    }

    /// Silences servo `id` (it answers nothing) or lets it answer again.
    pub fn set_silent(&mut self, id: u8, silent: bool) {
        if let Some(servo) = self.servo_mut(id) {
            servo.set_silent(silent);
        }
    }

    /// Sets the slowness factor of every servo.
    pub fn set_slow_factor(&mut self, factor: f64) {
        for servo in &mut self.servos {
            servo.set_slow_factor(factor);
        }
    }

    /// True angle of servo `id` at `now_us`, degrees (for drawing).
    pub fn angle_deg(&self, id: u8, now_us: u64) -> Option<f64> {
        self.servo(id).map(|s| s.angle_deg(now_us))
    }

    /// Angle of servo `id` at `now_us` as it reports it, 0.1°.
    pub fn angle_tenths_at(&self, id: u8, now_us: u64) -> Option<i16> {
        self.servo(id).map(|s| s.angle_tenths(now_us))
    }

    /// The servos hear `bytes`, the last of which finished arriving at
    /// `now_us` (earlier ones [`super::BYTE_TIME_US`] apart before it). Returns each
    /// answer as `(ready_at_us, frame bytes)`: `ready_at_us` is when its
    /// first byte starts on the wire, [`PROCESSING_DELAY_US`] after the
    /// request's last byte, or later if the line is still busy with an
    /// earlier answer; each answer then occupies the line for its own byte
    /// time ([`wire_time_us`]).
    pub fn receive(&mut self, now_us: u64, bytes: &[u8]) -> Vec<(u64, Vec<u8>)> {
        let mut answers = Vec::new();
        let n = bytes.len();
        for (i, &byte) in bytes.iter().enumerate() {
            let byte_end_us = now_us.saturating_sub(wire_time_us(n - 1 - i));
            self.decoder.push(byte);
            while let Some(event) = self.decoder.poll() {
                match event {
                    Ok(request) => self.handle(byte_end_us, &request, &mut answers),
                    Err(_) => self.decode_errors += 1,
                }
            }
        }
        answers
    }

    fn handle(&mut self, end_us: u64, request: &Request, answers: &mut Vec<(u64, Vec<u8>)>) {
        let frame = request.to_frame().map(|f| f.to_vec()).unwrap_or_default();
        self.frames.push(BusFrame {
            t_us: end_us.saturating_sub(wire_time_us(frame.len())),
            direction: BusDirection::Tx,
            bytes: frame,
        });
        let mut frames: Vec<Vec<u8>> = Vec::new();
        for (servo, unplugged) in self.servos.iter_mut().zip(&self.unplugged) {
            if *unplugged {
                continue;
            }
            let Some(response) = servo.execute(end_us, request) else {
                continue;
            };
            if let Ok(frame) = response.to_frame() {
                frames.push(frame.to_vec());
            }
        }
        let frame = match frames.len() {
            0 => None,
            1 => frames.pop(),
            _ => Some(collide(&frames)),
        };
        if let Some(frame) = frame {
            let start = (end_us + PROCESSING_DELAY_US).max(self.line_free_at_us);
            self.line_free_at_us = start + wire_time_us(frame.len());
            self.frames.push(BusFrame {
                t_us: start,
                direction: BusDirection::Rx,
                bytes: frame.to_vec(),
            });
            answers.push((start, frame.to_vec()));
        }
    }

    /// Every complete frame seen so far (requests as decoded, responses as
    /// sent), in order.
    pub fn frames(&self) -> &[BusFrame] {
        &self.frames
    }

    /// Takes the frame log, leaving it empty.
    pub fn take_frames(&mut self) -> Vec<BusFrame> {
        std::mem::take(&mut self.frames)
    }

    /// Request bytes that did not form a valid frame (bad length, bad
    /// checksum, unknown code) so far.
    pub fn decode_errors(&self) -> u64 {
        self.decode_errors
    }
}

/// What the controller receives when `frames` (two or more) are sent at
/// once: their bytewise AND, as long as the longest, checksum inverted
/// (see [`SimServoBus`]).
fn collide(frames: &[Vec<u8>]) -> Vec<u8> {
    let len = frames.iter().map(Vec::len).max().unwrap_or(0);
    let mut line = vec![0xFF; len];
    for frame in frames {
        for (wire, byte) in line.iter_mut().zip(frame) {
            *wire &= byte;
        }
    }
    if let Some(checksum) = line.last_mut() {
        *checksum = !*checksum;
    }
    line
}
