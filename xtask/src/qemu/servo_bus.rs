//! The servo bus of the emulated board: the simulator's own FashionStar
//! servos (`laser-sim`'s `servo_model`: the same request decoder, motion
//! model and fault injection as `cargo xtask sim`) answering the bytes the
//! firmware sends on UART1, through QEMU's chardev socket. Time is the host
//! clock since QEMU started (under `-icount shift=0` the board's clock
//! follows it while the CPU sleeps).

use std::io::{Read, Write};
use std::os::unix::net::UnixStream;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use laser_sim::recorder::{CorruptedFrame, Direction, FrameRecord};
use laser_sim::servo_model::{BusDirection, SimServoBus};
use laser_sim::servo_port::FaultInjector;

/// The servos and what crossed the bus.
pub struct ServoSide {
    /// The simulated servos.
    pub bus: SimServoBus,
    /// The faults' effect.
    pub injector: FaultInjector,
    /// Every frame: requests as the servos decoded them, answers as sent
    /// (damaged when a fault damaged them), host µs.
    pub frames: Vec<FrameRecord>,
    /// Answers the fault injection damaged (their clean bytes).
    pub damaged: Vec<CorruptedFrame>,
}

impl ServoSide {
    /// Feeds `bytes`, received at `now_us`, to the servos; returns the
    /// answer bytes to send back.
    pub fn receive(&mut self, now_us: u64, bytes: &[u8]) -> Vec<u8> {
        self.injector.apply_silence(&mut self.bus, now_us);
        let answers = self.bus.receive(now_us, bytes);
        for frame in self.bus.take_frames() {
            if frame.direction == BusDirection::Tx {
                self.frames.push(FrameRecord {
                    t_us: frame.t_us,
                    direction: Direction::Tx,
                    bytes: frame.bytes,
                });
            }
        }
        let mut out = Vec::new();
        for (ready_at_us, mut answer) in answers {
            let sent = answer.clone();
            self.injector.damage(&mut answer);
            if answer != sent {
                self.damaged.push(CorruptedFrame {
                    t_us: ready_at_us,
                    sent,
                    received: answer.clone(),
                });
            }
            self.frames.push(FrameRecord {
                t_us: ready_at_us,
                direction: Direction::Rx,
                bytes: answer.clone(),
            });
            out.extend_from_slice(&answer);
        }
        out
    }
}

/// Serves the bus on `stream` until QEMU closes it.
pub fn serve(mut stream: UnixStream, side: Arc<Mutex<ServoSide>>, t0: Instant) {
    let mut buf = [0u8; 256];
    loop {
        let n = match stream.read(&mut buf) {
            Ok(0) | Err(_) => return,
            Ok(n) => n,
        };
        let now_us = t0.elapsed().as_micros() as u64;
        let answer = match side.lock() {
            Ok(mut side) => side.receive(now_us, &buf[..n]),
            Err(_) => return,
        };
        if !answer.is_empty() && stream.write_all(&answer).is_err() {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fashionstar::{Message, Request};
    use laser_sim::servo_port::{BusFaults, SilentWindow};

    fn side(faults: BusFaults) -> ServoSide {
        ServoSide {
            bus: SimServoBus::new(&[0, 1], 1.0),
            injector: FaultInjector::new(faults, 7),
            frames: Vec::new(),
            damaged: Vec::new(),
        }
    }

    fn ping(id: u8) -> Vec<u8> {
        Request::Ping { id }.to_frame().unwrap().to_vec()
    }

    #[test]
    fn a_ping_split_over_reads_gets_one_answer_and_a_silent_servo_none() {
        let mut bus = side(BusFaults {
            silent: vec![SilentWindow {
                id: 1,
                from_ms: 10,
                until_ms: None,
            }],
            ..BusFaults::default()
        });
        let frame = ping(0);
        let (a, b) = frame.split_at(3);
        assert!(bus.receive(1_000, a).is_empty());
        let answer = bus.receive(1_100, b);
        assert!(!answer.is_empty());
        assert_eq!(bus.frames.len(), 2);
        assert!(
            !bus.receive(5_000, &ping(1)).is_empty(),
            "before the silence"
        );
        assert!(
            bus.receive(20_000, &ping(1)).is_empty(),
            "silent from 10 ms"
        );
    }
}
